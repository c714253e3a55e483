"""The GNC error budget (``rocketmc budget``): what each navigation error source costs the closed loop.

A closed-loop campaign on its navigation filters or raw sensors is flown again with each error source
alone (every other source off), with all of them (the campaign as written), with none (every source off:
the filters on perfect sensors, carrying the truth's field), and as two references: perfect navigation
(``navigation = "truth"``) and the controller off. Every row has the campaign's seed and N, so realization i meets
the same winds and draws everything else the same in every row (each dispersion, and each sensor's noise, has its
own random stream: ``campaign/sampling.py``). Per row: the 95 % landing ellipse's area, its paired ratios to the
other rows, the navigation and control metrics of ``sim/outputs.py`` (medians and 95th percentiles) and the failed
flights.

A source is an entry of ``SOURCES``: a name, a description, the config overrides that switch it off (dotted path
-> value, applied by ``with_overrides(campaign, values=...)``, the campaign loaded again with them) and why switching
it off would change nothing in a campaign (its sensor is not read, or it has no error already); such a source is
reported, not flown. A sensor's errors are switched off by its ``truth_only``; the reference field's
(``field_model``) by giving the filters the truth's model and zeroing the truth's anomaly, its dispersions removed.
Each row is flown with ``campaign.run_chunks`` (one compilation per row: a sensor's ``truth_only`` is a static
switch).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..campaign.loader import with_overrides
from ..campaign.record import Campaign
from ..campaign.runner import run_chunks
from ..campaign.schema import CampaignConfig
from ..errors import RocketmcError
from ..gnc.navigation import NavigationMode
from ..sim.outputs import CONTROL_METRICS, NAVIGATION_METRICS
from ..ellipse import MIN_BOOTSTRAP_POINTS, confidence_ellipse, ellipse_area_m2, percentile_interval

LEVEL = 0.95
"""Confidence level of the landing ellipses."""
MIN_REALIZATIONS = MIN_BOOTSTRAP_POINTS
"""Fewest realizations a budget flies: below it, ellipses and their bootstrap intervals mean little."""


class BudgetError(RocketmcError, ValueError):
    """A campaign or a request the budget cannot serve; one line."""


@dataclass(frozen=True)
class Source:
    """A navigation error source: ``name``, ``description``; ``off(config)``: the config overrides (dotted path ->
    value) that switch it off; ``idle(config)``: why switching it off changes nothing in ``config`` (its part is
    not read or has no error), None when it has to be flown."""

    name: str
    description: str
    off: Callable[[CampaignConfig], dict[str, object]]
    idle: Callable[[CampaignConfig], str | None]


SENSOR_ERRORS = ("bias", "bias_std", "bias_walk", "noise_density", "noise_std", "vibration_per_kpa", "scale_factor",
                 "scale_factor_std", "cross_axis", "cross_axis_std", "misalignment_deg", "misalignment_std_deg",
                 "hard_iron", "hard_iron_std", "soft_iron_std", "lsb", "position_noise_m", "velocity_noise_mps",
                 "sinusoid_amplitude_m")  # fmt: skip
"""A sensor's error fields (docs/sensors.md): all zero (or absent), with an identity soft-iron matrix and no
dispersion of the sensor's values, and it has no error. Its range is not counted: it only clips."""
IDENTITY = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]


def sensor_read(config: CampaignConfig, sensor: str) -> bool:
    """Whether the controller's navigation reads ``sensor`` (gnc/navigation.py): on raw sensors ("sensors") the
    gyroscope, the GNSS, the accelerometer (liftoff) and the canard feedback (the LQI's actuator states); on the
    filters also the magnetometer and, with its update on, the barometer."""
    navigation = NavigationMode(config.gnc.navigation)
    if sensor in ("accelerometer", "gyroscope", "gnss", "canard_feedback"):
        return navigation is not NavigationMode.TRUTH
    if sensor == "magnetometer":
        return navigation is NavigationMode.FILTERS
    if sensor == "barometer":
        return navigation is NavigationMode.FILTERS and config.gnc.filters.position.barometer
    return False


def _sensor_idle(sensor: str) -> Callable[[CampaignConfig], str | None]:
    def idle(config: CampaignConfig) -> str | None:
        if not sensor_read(config, sensor):
            return f"not read by navigation = {config.gnc.navigation!r}"
        values = getattr(config.avionics, sensor)
        if values.truth_only:
            return "already perfect (truth_only)"
        errors = [v for name in SENSOR_ERRORS for v in np.ravel(getattr(values, name, None) or 0.0)]
        dispersed = any(path.startswith(f"avionics.{sensor}.") for path in config.dispersions)
        soft_iron = getattr(values, "soft_iron", IDENTITY)
        if not any(errors) and not dispersed and list(soft_iron) == IDENTITY:
            return "already perfect (no error term; its range only clips)"
        return None

    return idle


def _sensor(sensor: str, description: str) -> Source:
    return Source(sensor, description, lambda config: {f"avionics.{sensor}.truth_only": True}, _sensor_idle(sensor))


ANOMALY = "environment.magnetic_field.anomaly_nt"
"""The truth's field anomaly [nT, NED] (its elements ``.0``-``.2``), which the filters never know."""


def _field_model_off(config: CampaignConfig) -> dict[str, object]:
    """The overrides that give the filters the truth's field: the MEKF carries the environment's model, and the
    truth's anomaly is zero and not dispersed (only what differs from that)."""
    truth, carried = config.environment.magnetic_field, config.gnc.filters.attitude.field_model
    off: dict[str, object] = {} if carried in (None, truth.model) else {"gnc.filters.attitude.field_model": truth.model}
    off.update({f"{ANOMALY}.{i}": 0.0 for i, value in enumerate(truth.anomaly_nt) if value != 0.0})
    off.update({f"dispersions.{ANOMALY}.{i}": None for i in range(3) if f"{ANOMALY}.{i}" in config.dispersions})
    return off


def _field_model_idle(config: CampaignConfig) -> str | None:
    if not sensor_read(config, "magnetometer"):
        return f"not read by navigation = {config.gnc.navigation!r}"
    if not _field_model_off(config):
        return "already perfect (the filters carry the truth's model; no anomaly)"
    return None


SOURCES: dict[str, Source] = {s.name: s for s in (
    _sensor("accelerometer", "the accelerometer's errors (bias, scale, cross-axis, misalignment, noise, walk, vibration)"),
    _sensor("gyroscope", "the gyroscope's errors (bias, scale, cross-axis, misalignment, noise, walk, vibration)"),
    _sensor("magnetometer", "the magnetometer's errors (bias, hard and soft iron, misalignment, noise)"),
    _sensor("barometer", "the barometer's errors (bias, noise, quantisation)"),
    _sensor("gnss", "the GNSS receiver's errors (white noise per fix, slow sinusoidal bias)"),
    _sensor("canard_feedback", "the canard position sensors' errors"),
    Source("field_model", "the reference field's error (the filters' field model against the truth's, its anomaly)",
           _field_model_off, _field_model_idle),
)}  # fmt: skip
"""The error sources, by name: each sensor's errors, then the filters' reference field; a later one (a fault) is one
entry more."""


@dataclass
class Row:
    """A row of the budget: ``name``, ``kind`` ("campaign", "none", "source" or "reference"), ``description``;
    ``campaign``: what it flies (None: not flown, ``reason`` says why); ``outputs``: its flights' outputs by name,
    N each, once flown; ``compile_s``, ``flight_s``: the time its compilation and its flights took [s]."""

    name: str
    kind: str
    description: str
    campaign: Campaign | None
    reason: str | None = None
    outputs: dict[str, np.ndarray] | None = None
    compile_s: float = 0.0
    flight_s: float = 0.0


def check_campaign(campaign: Campaign) -> None:
    """A BudgetError unless ``campaign`` flies a controller on navigation errors with enough realizations."""
    config = campaign.config
    if config.gnc is None:
        raise BudgetError("no [gnc] section: the budget needs a closed-loop campaign (navigation 'filters' or 'sensors')")
    if NavigationMode(config.gnc.navigation) is NavigationMode.TRUTH:
        raise BudgetError("gnc.navigation is 'truth': no navigation errors to budget (use 'filters' or 'sensors')")
    if config.n_realizations < MIN_REALIZATIONS:
        raise BudgetError(f"{config.n_realizations} realizations: the ellipses need at least {MIN_REALIZATIONS}")


def budget_rows(campaign: Campaign, sources: Sequence[str] | None = None, references: bool = True) -> list[Row]:
    """The rows of ``campaign``'s budget, not yet flown: "all" (the campaign), "none" (every source of ``SOURCES``
    off), each of ``sources`` (default: all of ``SOURCES``) alone, then with ``references`` "truth" (perfect
    navigation) and "off" (no controller). Sources that change nothing and the rows that would fly another row's
    campaign again are not flown (``Row.reason``)."""
    check_campaign(campaign)
    names = list(SOURCES) if sources is None else list(dict.fromkeys(sources))  # once each, in the order given
    unknown = [name for name in names if name not in SOURCES]
    if unknown:
        raise BudgetError(f"unknown source(s) {', '.join(unknown)} (known: {', '.join(SOURCES)})")
    config = campaign.config
    idle = {name: source.idle(config) for name, source in SOURCES.items()}
    off = {name: source.off(config) for name, source in SOURCES.items()}
    rows = [Row("all", "campaign", "every source as the campaign has it", campaign)]
    busy = any(reason is None for reason in idle.values())
    rows.append(Row("none", "none", "every source off: navigation on perfect sensors and the truth's field",
                    with_overrides(campaign, values=_merged(off.values())) if busy else None,
                    None if busy else "every source changes nothing: the same flights as 'all'"))  # fmt: skip
    for name in names:
        others = _merged(overrides for other, overrides in off.items() if other != name)
        reason = None if idle[name] is None else f"{idle[name]}: the same flights as 'none'"
        rows.append(Row(name, "source", f"{SOURCES[name].description} alone",
                        None if reason else with_overrides(campaign, values=others), reason))  # fmt: skip
    if references:
        rows.append(Row("truth", "reference", "perfect navigation (navigation = 'truth')",
                        with_overrides(campaign, navigation="truth")))  # fmt: skip
        rows.append(Row("off", "reference", "controller off (canards neutral)", with_overrides(campaign, controller=False)))
    return rows


def _merged(overrides: Iterable[Mapping[str, object]]) -> dict[str, object]:
    merged = {}
    for one in overrides:
        merged.update(one)
    return merged


def fly_rows(rows: Sequence[Row], log: Callable[[str], None] = lambda message: None) -> list[Row]:
    """Fly each row that has a campaign (``run_chunks``, its chunks gathered in order), saying what it does with
    ``log``; the rows, with their outputs."""
    flown = [row for row in rows if row.campaign is not None]
    for i, row in enumerate(flown):
        log(f"row {i + 1}/{len(flown)} {row.name}: compiling")
        chunks = run_chunks(row.campaign)
        row.compile_s = next(chunks)
        parts = []
        for chunk in chunks:
            parts.append(chunk.outputs)
            row.flight_s += chunk.seconds
        row.outputs = {name: np.concatenate([part[name] for part in parts]) for name in parts[0]}
        failed = int((row.outputs["status"] != 0).sum())
        log(f"row {i + 1}/{len(flown)} {row.name}: compiled in {row.compile_s:.1f} s, {len(row.outputs['status'])} "
            f"flights in {row.flight_s:.1f} s{f', {failed} not ok' if failed else ''}")  # fmt: skip
    return list(rows)


def _landed(outputs: Mapping[str, np.ndarray]) -> np.ndarray:
    """Which flights are ok (status 0) with a finite impact point."""
    return (outputs["status"] == 0) & np.isfinite(outputs["impact_north_m"]) & np.isfinite(outputs["impact_east_m"])


def _ratio(row: Mapping[str, np.ndarray], base: Mapping[str, np.ndarray]) -> dict | None:
    """The ratio of ``row``'s ellipse area to ``base``'s over the flights landed in both (paired: the same
    realizations), with its 95 % percentile-bootstrap interval; None with too few such flights or no base area."""
    kept = _landed(row) & _landed(base)
    if kept.sum() < MIN_BOOTSTRAP_POINTS:
        return None
    samples = tuple(np.stack([o["impact_north_m"][kept], o["impact_east_m"][kept]]) for o in (row, base))
    if not ellipse_area_m2(*samples[1], LEVEL) > 0.0:
        return None

    def ratio(run, baseline, axis=-1):
        return ellipse_area_m2(*run, LEVEL, axis) / ellipse_area_m2(*baseline, LEVEL, axis)

    return {"ratio": float(ratio(*samples)), "interval": list(percentile_interval(samples, ratio, paired=True)),
            "n_used": int(kept.sum())}  # fmt: skip


def _percentiles(values: np.ndarray) -> dict:
    """The median and 95th percentile of the finite ``values`` and how many there are (None when none)."""
    values = values[np.isfinite(values)]
    if values.size == 0:
        return {"n": 0, "p50": None, "p95": None}
    return {"n": int(values.size), "p50": float(np.percentile(values, 50.0)), "p95": float(np.percentile(values, 95.0))}


RATIO_BASES = ("none", "truth", "off")
"""The rows every row's area is compared with, paired."""


def summarize_budget(campaign: Campaign, rows: Sequence[Row]) -> dict:
    """The budget as a JSON-able dict: the campaign, N, seed, level; per row its name, kind, description, whether
    flown (else why not), failed flights, the ellipse (``Ellipse.to_dict``, m) and the paired ratios of its area to
    the rows of ``RATIO_BASES`` ({ratio, interval, n_used}; None where that row was not flown), and the median
    and 95th percentile of each navigation and control metric (SI units, ``metrics_units``); then the source
    alone whose ellipse is the largest against "none" (``costliest``)."""
    config = campaign.config
    outputs = {row.name: row.outputs for row in rows if row.outputs is not None}
    if "none" not in outputs:  # no source to switch off: 'none' flies the campaign
        outputs["none"] = outputs.get("all")
    summary_rows = []
    for row in rows:
        entry = {"name": row.name, "kind": row.kind, "description": row.description, "flown": row.outputs is not None,
                 "reason": row.reason}  # fmt: skip
        if row.outputs is not None:
            o = row.outputs
            landed = _landed(o)
            north, east = o["impact_north_m"][landed], o["impact_east_m"][landed]
            entry.update({
                "n": int(o["status"].size), "failed": int((o["status"] != 0).sum()), "n_landed": int(landed.sum()),
                "ellipse": confidence_ellipse(north, east, LEVEL).to_dict() if north.size >= 3 else None,
                "ratios": {base: None if outputs.get(base) is None or base == row.name else _ratio(o, outputs[base])
                           for base in RATIO_BASES},
                "metrics": {name: _percentiles(o[name]) for name in (*NAVIGATION_METRICS, *CONTROL_METRICS) if name in o},
                "compile_s": row.compile_s, "flight_s": row.flight_s,
            })  # fmt: skip
        summary_rows.append(entry)
    costs = [(r["ratios"]["none"]["ratio"], r["name"]) for r in summary_rows
             if r["kind"] == "source" and r["flown"] and r["ratios"]["none"] is not None]  # fmt: skip
    costliest = None
    if costs:
        name = max(costs)[1]
        ratio = next(r for r in summary_rows if r["name"] == name)["ratios"]["none"]
        costliest = {"source": name, **ratio, "resolved": ratio["interval"][0] > 1.0}
    units = {name: metric.unit for name, metric in {**NAVIGATION_METRICS, **CONTROL_METRICS}.items()}
    return {"campaign": config.name, "n_realizations": config.n_realizations, "seed": config.seed, "level": LEVEL,
            "navigation": config.gnc.navigation, "rows": summary_rows, "costliest": costliest,
            "metrics_units": units}  # fmt: skip


def budget(campaign: Campaign, sources: Sequence[str] | None = None, references: bool = True,
           log: Callable[[str], None] = lambda message: None) -> tuple[dict, list[Row]]:  # fmt: skip
    """``campaign``'s error budget: (``summarize_budget``'s dict, the flown ``Row``s); ``sources``, ``references``
    as ``budget_rows``; ``log``: progress lines."""
    rows = fly_rows(budget_rows(campaign, sources, references), log)
    return summarize_budget(campaign, rows), rows


SHOWN_METRICS = (("attitude_error_rms_window_rad", "att. err. RMS [deg]", np.degrees),
                 ("velocity_error_burnout_mps", "vel. err. burnout [m/s]", float),
                 ("tracking_error_rms_rad", "tracking RMS [deg]", np.degrees))  # fmt: skip
"""The metrics ``format_budget`` shows (the JSON has them all): name, column title, SI to the shown unit."""


def format_budget(summary: dict) -> str:
    """The budget as a text table: per row the failed flights, the ellipse area [km²], its ratios to the rows
    "none", "truth" and "off" (paired, with the 95 % bootstrap interval against "none") and the median / 95th
    percentile of ``SHOWN_METRICS``; then the costliest source."""
    header = ["row", "failed", "area [km²]", "× none (95 % CI)", "× truth", "× off", *(t for _, t, _ in SHOWN_METRICS)]
    table = []
    for r in summary["rows"]:
        if not r["flown"]:
            table.append([r["name"], f"not flown: {r['reason']}"])
            continue
        area = "–" if r["ellipse"] is None else f"{r['ellipse']['area_m2'] / 1e6:.4g}"
        ratios = {k: v for k, v in r["ratios"].items()}
        none = ratios["none"]
        cells = [r["name"], str(r["failed"]), area,
                 "–" if none is None else f"{none['ratio']:.3f} ({none['interval'][0]:.3f}…{none['interval'][1]:.3f})",
                 *("–" if ratios[k] is None else f"{ratios[k]['ratio']:.3f}" for k in ("truth", "off"))]  # fmt: skip
        for name, _, convert in SHOWN_METRICS:
            stats = r["metrics"].get(name)
            cells.append("–" if stats is None or stats["n"] == 0 else
                         f"{convert(stats['p50']):.3g} / {convert(stats['p95']):.3g}")  # fmt: skip
        table.append(cells)
    widths = [max(len(c[i]) for c in [header, *table] if i < len(c) and (len(c) > 2 or i == 0)) for i in range(len(header))]
    lines = [f"{summary['campaign']}: GNC error budget, N = {summary['n_realizations']}, seed {summary['seed']}, "
             f"navigation {summary['navigation']!r}; {100 * summary['level']:g} % landing ellipses, ratios paired "
             "(the flights landed in both rows); metrics: median / 95th percentile", ""]  # fmt: skip
    lines.append("  ".join(h.ljust(w) for h, w in zip(header, widths)).rstrip())
    for cells in table:
        lines.append(("  ".join(c.ljust(w) for c, w in zip(cells, widths)) if len(cells) > 2 else
                      f"{cells[0].ljust(widths[0])}  {cells[1]}").rstrip())  # fmt: skip
    costliest = summary["costliest"]
    if costliest is not None:
        low, high = costliest["interval"]
        verdict = "" if costliest["resolved"] else "; its interval holds 1: not resolved at this N"
        lines += ["", f"costliest source alone: {costliest['source']}, {costliest['ratio']:.3f}× the ellipse area of "
                      f"'none' (95 % CI {low:.3f}…{high:.3f}){verdict}"]  # fmt: skip
    return "\n".join(lines)


LOG_SCALE_SPAN = 10.0
"""``plot_budget`` draws its areas on a log scale when the largest is more than this times the smallest."""


def plot_budget(summary: dict, path: str | Path | None = None):
    """A bar chart of the ellipse area [km²] of each flown row but the references, whose areas ("truth", "off") are
    horizontal lines (a log scale when they span more than ``LOG_SCALE_SPAN``); saved to ``path`` if given."""
    from matplotlib.figure import Figure

    from .plots import save_figure

    flown = [r for r in summary["rows"] if r["flown"] and r["ellipse"] is not None]
    bars = [r for r in flown if r["kind"] != "reference"]
    colors = {"campaign": "tab:blue", "none": "tab:green", "source": "tab:orange"}
    fig = Figure(figsize=(max(7.0, 1.5 + 1.3 * len(bars)), 4.5), layout="constrained")
    ax = fig.add_subplot()
    areas_km2 = [r["ellipse"]["area_m2"] / 1e6 for r in flown]
    if max(areas_km2) > LOG_SCALE_SPAN * min(areas_km2):
        ax.set_yscale("log")
    drawn = ax.bar([r["name"] for r in bars], [r["ellipse"]["area_m2"] / 1e6 for r in bars],
                   color=[colors[r["kind"]] for r in bars])  # fmt: skip
    ax.bar_label(drawn, fmt="%.4g", fontsize="small")
    for r, style in zip([r for r in flown if r["kind"] == "reference"], ("--", ":")):
        ax.axhline(r["ellipse"]["area_m2"] / 1e6, color="k", linestyle=style,
                   label=f"{r['name']}: {r['description']}, {r['ellipse']['area_m2'] / 1e6:.4g} km²")  # fmt: skip
    ax.set_ylabel(f"{100 * summary['level']:g} % landing ellipse area [km²]")
    ax.set_title(f"{summary['campaign']}: GNC error budget (N = {summary['n_realizations']}, seed {summary['seed']})")
    ax.grid(True, axis="y", alpha=0.4)
    if any(r["kind"] == "reference" for r in flown):
        ax.legend(loc="best", fontsize="small")
    if path is not None:
        save_figure(fig, path)
    return fig

"""Reading campaign result files (HDF5) and summarising them.

Layout read here: ``/outputs/<name>`` 1-D datasets (row = realization, ``attrs["unit"]``),
``/outputs/status`` int (0 = ok, ``attrs["codes"]`` a JSON object code -> message),
``/inputs/<name>`` 1-D sampled dispersions, and root attributes such as ``campaign_name``,
``seed``, ``n_realizations`` and ``complete``. Impact points are north/east [m] from the pad
(NED world frame). ``/trajectories/<index>`` (only with ``run --trajectories``): realization index's time
series, one 1-D dataset per column (``attrs["unit"]``, ``attrs["description"]``), decimated as the group's
``description`` says, every ``interval_s`` attribute seconds.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

import h5py
import numpy as np
import pandas as pd

from ..errors import RocketmcError
from ..ellipse import MIN_BOOTSTRAP_POINTS, bootstrap_intervals, confidence_ellipse

SUMMARY_LEVELS = (0.5, 0.95, 0.99)
"""Confidence levels of the impact ellipses in :func:`summarize`."""

_PERCENTILES = {"p5": 5.0, "p50": 50.0, "p95": 95.0}
REQUIRED_OUTPUTS = ("status", "impact_north_m", "impact_east_m")
"""Datasets every result file has (docs/conventions.md) and the report reads."""
DIVERGED = "navigation_diverged"
"""The per-flight flag of a navigation estimate that diverged (``sim.outputs.NAVIGATION_METRICS``; flights on the
navigation filters only)."""


class ResultFileError(RocketmcError, ValueError):
    """A file that is not a complete rocketmc result file; one line naming it."""


@dataclass(frozen=True)
class Run:
    """A loaded campaign: outputs and inputs per realization, root attributes, units
    (dataset name -> unit string), status codes (code -> message) and the realizations whose trajectories
    the file keeps (``load_trajectories``)."""

    outputs: pd.DataFrame
    inputs: pd.DataFrame
    attrs: dict
    units: dict[str, str]
    status_codes: dict[int, str]
    trajectories: tuple[int, ...] = ()

    @property
    def ok(self) -> np.ndarray:
        """Boolean mask of realizations with status 0."""
        if "status" not in self.outputs:
            raise ResultFileError("result file has no /outputs/status dataset")
        return self.outputs["status"].to_numpy() == 0

    @property
    def landed(self) -> np.ndarray:
        """Boolean mask of ok realizations with finite impact coordinates."""
        return self.ok & np.isfinite(self._impacts()).all(axis=0)

    @property
    def has_impact(self) -> np.ndarray:
        """Boolean mask of realizations, of any status, with finite impact coordinates (a tumbled flight
        still lands; one stopped on a NaN state has no impact point)."""
        return np.isfinite(self._impacts()).all(axis=0)

    @property
    def diverged(self) -> np.ndarray:
        """Boolean mask of realizations, of any status, whose navigation estimate diverged (all False in a run
        without the flag: no navigation filters)."""
        if DIVERGED not in self.outputs:
            return np.zeros(len(self.outputs), dtype=bool)
        return self.outputs[DIVERGED].to_numpy(dtype=float) > 0.5

    @property
    def overrides(self) -> dict:
        """What the run switched from its campaign file (``Campaign.overrides``; empty if nothing or unrecorded)."""
        return json.loads(self.attrs.get("overrides", "{}"))

    @property
    def label(self) -> str:
        """The campaign's name and the switches the run was flown with: ``lynx_ballistic_gnc_1s (controller off)``."""
        name = self.attrs.get("campaign_name", "")
        return f"{name} ({switches_text(self.overrides)})" if self.overrides else name

    def _impacts(self) -> np.ndarray:
        """(2, N) impact points (north, east) [m] of every realization."""
        return self.outputs[["impact_north_m", "impact_east_m"]].to_numpy(dtype=float).T

    def ok_impacts(self, where: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """``(north, east)`` impact points [m] of the realizations in the boolean mask ``where``
        (default: ``landed``, the ok ones with finite coordinates)."""
        north, east = self._impacts()[:, self.landed if where is None else where]
        return north, east


def switches_text(overrides: dict) -> str:
    """``Campaign.overrides`` in words: ``controller off, aero_model simplified, rocket.dry_mass_kg = 28``."""
    def word(name, value):
        if isinstance(value, bool):
            return f"{name} {'on' if value else 'off'}"
        return f"{name} {value}" if "." not in name else f"{name} = {json.dumps(value)}"
    return ", ".join(word(name, value) for name, value in overrides.items())


def _native(value):
    """HDF5 attribute value as a plain Python (JSON-serialisable) object."""
    if isinstance(value, bytes):
        return value.decode()
    if isinstance(value, np.ndarray):
        return [_native(v) for v in value.tolist()]
    if isinstance(value, np.generic):
        return value.item()
    return value


def _open(path) -> h5py.File:
    """The result file ``path``, open to read; ResultFileError unless it is a complete one."""
    try:
        f = h5py.File(path, "r")
    except FileNotFoundError:
        raise ResultFileError(f"{path}: file not found") from None
    except OSError as e:
        raise ResultFileError(f"{path}: not an HDF5 file, or damaged ({str(e).splitlines()[0]})") from None
    try:
        if not isinstance(f.get("outputs"), h5py.Group):
            raise ResultFileError(f"{path}: not a rocketmc result file (no /outputs group)")
        if not bool(f.attrs.get("complete", False)):
            raise ResultFileError(f"{path}: result file is incomplete (run still in progress or aborted)")
        missing = [name for name in REQUIRED_OUTPUTS if not isinstance(f["outputs"].get(name), h5py.Dataset)]
        if missing:
            raise ResultFileError(f"{path}: not a rocketmc result file (no {', '.join('/outputs/' + m for m in missing)})")
    except BaseException:
        f.close()
        raise
    return f


def _read_group(f: h5py.File, name: str, path) -> tuple[pd.DataFrame, dict[str, str]]:
    """Every 1-D dataset of group ``name`` as DataFrame columns, plus their units."""
    group = f.get(name)
    if group is None:
        return pd.DataFrame(index=pd.RangeIndex(0, name="realization")), {}
    columns, units = {}, {}
    for key, item in group.items():
        if not isinstance(item, h5py.Dataset):
            continue
        if item.ndim != 1 or not np.issubdtype(item.dtype, np.number):
            raise ResultFileError(f"{path}: /{name}/{key} is not a 1-D array of numbers ({item.shape}, {item.dtype})")
        columns[key] = item[()]
        if "unit" in item.attrs:
            units[key] = _native(item.attrs["unit"])
    lengths = {len(v) for v in columns.values()}
    if len(lengths) > 1:
        raise ResultFileError(f"{path}: datasets in /{name} differ in length: {sorted(lengths)}")
    n = lengths.pop() if lengths else 0
    return pd.DataFrame(columns, index=pd.RangeIndex(n, name="realization")), units


def load_outputs(path: str | Path) -> pd.DataFrame:
    """Per-realization outputs of a complete result file (one column per ``/outputs`` dataset)."""
    with _open(path) as f:
        return _read_group(f, "outputs", path)[0]


def load_inputs(path: str | Path) -> pd.DataFrame:
    """Per-realization sampled dispersions of a complete result file (``/inputs`` datasets)."""
    with _open(path) as f:
        return _read_group(f, "inputs", path)[0]


def load_run(path: str | Path) -> Run:
    """Outputs, inputs, root attributes, units, status codes and kept trajectories of a complete result file."""
    with _open(path) as f:
        outputs, units = _read_group(f, "outputs", path)
        inputs, input_units = _read_group(f, "inputs", path)
        attrs = {k: _native(v) for k, v in f.attrs.items()}
        trajectories = tuple(sorted(int(name) for name in f.get("trajectories", {})))
        codes = {}
        if "status" in f["outputs"] and "codes" in f["outputs/status"].attrs:
            try:
                codes = {int(k): str(v) for k, v in json.loads(_native(f["outputs/status"].attrs["codes"])).items()}
            except (ValueError, AttributeError):
                raise ResultFileError(f"{path}: /outputs/status's codes attribute is not a JSON object of codes") from None
    expected = attrs.get("n_realizations")
    if expected is not None and len(outputs) != expected:
        raise ResultFileError(f"{path}: {len(outputs)} output rows but n_realizations = {expected}")
    if len(inputs.columns) and len(inputs) != len(outputs):
        raise ResultFileError(f"{path}: {len(inputs)} input rows but {len(outputs)} output rows")
    return Run(outputs, inputs, attrs, {**input_units, **units}, codes, trajectories)


def load_trajectories(path: str | Path) -> dict[int, pd.DataFrame]:
    """The kept trajectories of a complete result file (``run --trajectories``), by realization index, ascending:
    each a DataFrame of the columns in their stored order (strings decoded), units and meanings in its
    ``attrs["units"]`` (column -> (unit, description)), its flight's status code in ``attrs["status"]``; empty
    when the run kept none."""
    with _open(path) as f:
        trajectories = {}
        for name, group in sorted(f.get("trajectories", {}).items(), key=lambda item: int(item[0])):
            frame = pd.DataFrame({key: ds.asstr()[()] if ds.dtype.kind == "S" else ds[()] for key, ds in group.items()})
            frame.attrs = {"units": {key: (_native(ds.attrs["unit"]), _native(ds.attrs["description"]))
                                     for key, ds in group.items()}, "status": int(group.attrs["status"])}  # fmt: skip
            trajectories[int(name)] = frame
        return trajectories


def navigation_warnings(run: Run) -> list[str]:
    """One line if any flight's navigation estimate diverged (``Run.diverged``): how many, and that the ellipse,
    drawn from the ok flights, keeps them (they flew so); none otherwise."""
    diverged = run.diverged
    if not diverged.any():
        return []
    landed = int((diverged & run.landed).sum())
    return [f"{run.attrs.get('campaign_name', '')}: the navigation estimate diverged in {int(diverged.sum())} of "
            f"{len(diverged)} flights (/outputs/{DIVERGED}: attitude, velocity or NEES beyond its bound, "
            f"docs/navigation.md); {landed} of them are in the impact ellipses, which show the broken navigation's "
            "dispersion, not a working one's"]  # fmt: skip


FAULT_FLAG = ".happened"
"""The end of a fault's per-flight flag in ``/inputs``: ``faults.<fault>.happened``, 1 where the flight had it."""


def fault_rows(run: Run) -> list[dict]:
    """Per fault of the run (its ``/inputs/faults.<fault>.happened``): ``fault``, ``flights`` that had it, how many
    of them are ``not_ok`` (a status code), and the 95 % ellipse of the ok impact points ``with`` every flight and
    ``without`` the faulted ones (``Ellipse.to_dict()``; None below 3 points): what the fault costs."""
    rows = []
    for name in run.inputs.columns:
        if not (name.startswith("faults.") and name.endswith(FAULT_FLAG)):
            continue
        faulted = run.inputs[name].to_numpy(dtype=float) > 0.5
        ellipses = {}
        for label, where in (("with", run.landed), ("without", run.landed & ~faulted)):
            north, east = run.ok_impacts(where)
            ellipses[label] = confidence_ellipse(north, east, 0.95).to_dict() if north.size >= 3 else None
        rows.append({"fault": name.removeprefix("faults.").removesuffix(FAULT_FLAG), "flights": int(faulted.sum()),
                     "not_ok": int((faulted & ~run.ok).sum()), **ellipses})  # fmt: skip
    return rows


APOGEE_ERROR = "apogee_error_m"
"""The output of a run with air brakes: the apogee above the pad less their target."""


def apogee_target_m(run: Run) -> float | None:
    """The air brakes' target apogee above the pad [m] of ``run`` (apogee less ``APOGEE_ERROR``), None without."""
    if APOGEE_ERROR not in run.outputs:
        return None
    target = (run.outputs["apogee_agl_m"] - run.outputs[APOGEE_ERROR]).to_numpy(dtype=float)
    target = target[np.isfinite(target)]
    return float(np.median(target)) if target.size else None


def apogee_about(run: Run, target_m: float) -> dict | None:
    """The ok flights' apogee above the pad against ``target_m`` [m]: n, mean_error_m, rms_error_m, the error's
    central 95 % interval (2.5th to 97.5th percentile) ``interval_95_m``, and the fractions of flights within 1 % and
    5 % of the target; None without apogees."""
    error = run.outputs["apogee_agl_m"].to_numpy(dtype=float)[run.ok] - target_m
    error = error[np.isfinite(error)]
    if error.size == 0:
        return None
    return {
        "target_m": target_m, "n": int(error.size), "mean_error_m": float(error.mean()),
        "rms_error_m": float(np.sqrt(np.mean(error**2))),
        "interval_95_m": [float(x) for x in np.percentile(error, [2.5, 97.5])],
        "within_1_percent": float(np.mean(np.abs(error) <= 0.01 * target_m)),
        "within_5_percent": float(np.mean(np.abs(error) <= 0.05 * target_m)),
    }  # fmt: skip


def format_apogee_about(about: dict) -> str:
    """One line of ``apogee_about``."""
    low, high = about["interval_95_m"]
    return (f"{about['target_m']:.0f} m: mean error {about['mean_error_m']:+.1f} m, RMS {about['rms_error_m']:.1f} m, "
            f"95 % of flights {low:+.1f}…{high:+.1f} m, within 1 %: {100 * about['within_1_percent']:.1f} %, within 5 %: "
            f"{100 * about['within_5_percent']:.1f} %")  # fmt: skip


def _stat(x: float) -> float | None:
    """Float, with NaN/inf mapped to None (strict JSON has no NaN)."""
    return float(x) if math.isfinite(x) else None


def _metric_stats(values: np.ndarray) -> dict:
    """n, mean, std (ddof=1), min, p5, p50, p95, max of the finite values."""
    values = values[np.isfinite(values)]
    if values.size == 0:
        return {"n": 0, **{k: None for k in ("mean", "std", "min", *_PERCENTILES, "max")}}
    stats = {
        "n": int(values.size),
        "mean": _stat(values.mean()),
        "std": _stat(values.std(ddof=1)) if values.size > 1 else None,
        "min": _stat(values.min()),
    }
    stats.update({k: _stat(np.percentile(values, q)) for k, q in _PERCENTILES.items()})
    stats["max"] = _stat(values.max())
    return stats


def summarize(run: Run) -> dict:
    """JSON-serialisable summary of a run.

    Keys: ``campaign_name``, ``overrides`` (``Run.overrides``), ``seed``, ``rocketmc_version``, ``n_realizations``, ``n_ok``,
    ``status`` (list of code/message/count, every known code and any other code seen), ``failed`` (per
    code seen other than 0: code, message, count, ``landed`` with an impact point and
    ``no_impact_point``; these flights are left out of the metrics and ellipses),
    ``metrics`` (per output except status, over ok realizations and finite values: unit, n,
    mean, std (ddof=1), min, p5, p50, p95, max) and ``impact_ellipses`` (``Ellipse.to_dict()``
    at 50/95/99 % of the ok impact points; empty when fewer than 3 are available) and
    ``impact_ellipse_95_intervals`` (``bootstrap_intervals`` of the 95 % ellipse's area and centre;
    None below ``MIN_BOOTSTRAP_POINTS``) and ``navigation_diverged`` (flights of any status whose navigation
    estimate diverged, ``Run.diverged``; None without navigation filters) and ``faults`` (``fault_rows``: per fault
    the flights that had it and the 95 % ellipse with and without them; empty without faults) and ``warnings`` (what ``run`` warned of:
    the nominal rocket's static stability, flights beyond the aerodynamic method's validity, the file's
    ``warnings`` attribute; then ``navigation_warnings``) and ``trajectories`` (the realizations whose trajectories
    the file keeps, ascending) and ``apogee_target`` (with air brakes, ``apogee_about`` their target; else None).
    """
    ok = run.ok
    status = run.outputs["status"].to_numpy()
    seen, counts = np.unique(status, return_counts=True)
    count_of = dict(zip(seen.tolist(), counts.tolist()))
    codes = sorted(set(run.status_codes) | set(count_of))
    status_rows = [
        {
            "code": c,
            "message": run.status_codes.get(c, "ok" if c == 0 else "unknown"),
            "count": count_of.get(c, 0),
        }
        for c in codes
    ]
    failed = [
        {"code": s["code"], "message": s["message"], "count": s["count"],
         "landed": int((run.has_impact & (status == s["code"])).sum()),
         "no_impact_point": int((~run.has_impact & (status == s["code"])).sum())}
        for s in status_rows if s["code"] != 0 and s["count"]
    ]  # fmt: skip
    metrics = {
        name: {"unit": run.units.get(name, ""), **_metric_stats(col.to_numpy(dtype=float)[ok])}
        for name, col in run.outputs.items()
        if name != "status"
    }
    north, east = run.ok_impacts()
    ellipses = [
        {**e.to_dict(), "coverage": float(e.contains(north, east).mean())}
        for e in (confidence_ellipse(north, east, level) for level in SUMMARY_LEVELS)
    ] if north.size >= 3 else []  # fmt: skip
    intervals = bootstrap_intervals(north, east, 0.95) if north.size >= MIN_BOOTSTRAP_POINTS else None
    return {
        "campaign_name": run.attrs.get("campaign_name", ""),
        "overrides": run.overrides,
        "seed": run.attrs.get("seed"),
        "rocketmc_version": run.attrs.get("rocketmc_version", ""),
        "n_realizations": len(run.outputs),
        "n_ok": int(ok.sum()),
        "status": status_rows,
        "failed": failed,
        "metrics": metrics,
        "impact_ellipses": ellipses,
        "impact_ellipse_95_intervals": intervals,
        "navigation_diverged": int(run.diverged.sum()) if DIVERGED in run.outputs else None,
        "faults": fault_rows(run),
        "warnings": json.loads(run.attrs.get("warnings", "[]")) + navigation_warnings(run),
        "trajectories": list(run.trajectories),
        "apogee_target": None if (target := apogee_target_m(run)) is None else apogee_about(run, target),
    }


def _num(x: float | None) -> str:
    """About four significant figures, fixed-point where readable."""
    if x is None:
        return "-"
    ax = abs(x)
    if ax >= 1e7 or 0.0 < ax < 1e-2:
        return f"{x:.3e}"
    if ax >= 1000.0:
        return f"{x:.1f}"
    if ax >= 10.0:
        return f"{x:.2f}"
    return f"{x:.3f}"


def text_table(header: list[str], rows: list[list[str]], align: str) -> list[str]:
    """Aligned text table; ``align`` holds one "l" (left) or "r" (right) per column."""
    widths = [max(len(r[i]) for r in [header, *rows]) for i in range(len(header))]

    def line(cells):
        return "  " + "  ".join(
            c.ljust(w) if a == "l" else c.rjust(w) for c, w, a in zip(cells, widths, align)
        ).rstrip()

    return [line(header), *(line(r) for r in rows)]


def report(run: Run | str | Path) -> str:
    """What ``rocketmc report`` prints of a result file (a path, or a ``Run`` from ``load_run``): its status counts,
    metric statistics, ellipses and bootstrap intervals (``format_summary(summarize(run))``)."""
    return format_summary(summarize(run if isinstance(run, Run) else load_run(run)))


def format_summary(summary: dict) -> str:
    """Compact human-readable report of a :func:`summarize` dict."""
    out = [
        f"Campaign {summary['campaign_name']!r}  (seed {summary['seed']}, "
        f"rocketmc {summary['rocketmc_version']})",
        *([f"Flown with: {switches_text(summary['overrides'])} (the campaign file's setting overridden)"]
          if summary["overrides"] else []),  # fmt: skip
        f"Realizations: {summary['n_realizations']} total, {summary['n_ok']} ok",
        *([f"Trajectories kept (rocketmc.analysis.load_trajectories): realizations "
           f"{', '.join(map(str, summary['trajectories']))}"] if summary["trajectories"] else []),  # fmt: skip
        *(f"Warning: {line}" for line in summary["warnings"]),
        "",
        "Status",
        *text_table(
            ["code", "count", "message"],
            [[str(s["code"]), str(s["count"]), s["message"]] for s in summary["status"]],
            align="rrl",
        ),
        "",
    ]
    if summary["failed"]:
        out += ["Failed realizations (not in the metrics or ellipses; their impact points are drawn apart)"]
        out += text_table(
            ["code", "count", "landed", "no impact point", "message"],
            [[str(s["code"]), str(s["count"]), str(s["landed"]), str(s["no_impact_point"]), s["message"]]
             for s in summary["failed"]],
            align="rrrrl",
        )  # fmt: skip
        out.append("")
    out += ["Metrics (ok realizations)"]
    stat_keys = ["mean", "std", "min", *_PERCENTILES, "max"]
    out += text_table(
        ["metric", "unit", "n", *stat_keys],
        [
            [name, m["unit"], str(m["n"]), *(_num(m[k]) for k in stat_keys)]
            for name, m in summary["metrics"].items()
        ],
        align="ll" + "r" * (1 + len(stat_keys)),
    )
    out += ["", "Impact ellipses (north/east from pad)"]
    if summary["impact_ellipses"]:
        out += text_table(
            ["level", "N [m]", "E [m]", "a [m]", "b [m]", "az [deg]", "area [km^2]", "area [m^2]", "inside"],
            [
                [
                    f"{100 * e['level']:g} %",
                    f"{e['center_north_m']:.1f}",
                    f"{e['center_east_m']:.1f}",
                    f"{e['semi_major_m']:.1f}",
                    f"{e['semi_minor_m']:.1f}",
                    f"{e['orientation_deg']:.1f}",
                    f"{e['area_m2'] / 1e6:.4g}",
                    f"{e['area_m2']:.0f}",
                    f"{100 * e['coverage']:.1f} %",
                ]
                for e in summary["impact_ellipses"]
            ],
            align="r" * 9,
        )
        out.append("  (N, E: centre; a, b: semi-axes; az: major axis, clockwise from north; inside: the fraction of "
                   "ok impact points inside, the check on the ellipses' Gaussian fit)")  # fmt: skip
    if summary["impact_ellipse_95_intervals"]:
        i = summary["impact_ellipse_95_intervals"]
        out.append(f"  95 % ellipse, 95 % bootstrap intervals: area {i['area_m2'][0] / 1e6:.4g}–{i['area_m2'][1] / 1e6:.4g} "
                   f"km², centre N {i['center_north_m'][0]:.1f}…{i['center_north_m'][1]:.1f} m, "
                   f"E {i['center_east_m'][0]:.1f}…{i['center_east_m'][1]:.1f} m")  # fmt: skip
    else:
        out.append("  not available: fewer than 3 ok impact points")
    if summary["apogee_target"]:
        out += ["", "Apogee against the air brakes' target (ok realizations)", "  " + format_apogee_about(summary["apogee_target"])]
    if summary["faults"]:
        out += ["", "Faults (/inputs/faults.*): the 95 % ellipse of the ok flights with and without the faulted ones"]
        out += text_table(["fault", "flights", "not ok", "area with [km^2]", "without [km^2]", "change", "centre with N, E [m]",
                       "without N, E [m]"], [_fault_cells(f) for f in summary["faults"]], align="lrrrrrrr")  # fmt: skip
    return "\n".join(out)


def _fault_cells(row: dict) -> list[str]:
    """A ``fault_rows`` row as text: the ellipses' areas, the change from without to with, their centres."""
    with_, without = row["with"], row["without"]

    def area(e):
        return "-" if e is None else f"{e['area_m2'] / 1e6:.4g}"

    def centre(e):
        return "-" if e is None else f"{e['center_north_m']:.1f}, {e['center_east_m']:.1f}"

    change = "-" if with_ is None or without is None else f"{100 * (with_['area_m2'] / without['area_m2'] - 1):+.1f} %"
    return [row["fault"], str(row["flights"]), str(row["not_ok"]), area(with_), area(without), change, centre(with_),
            centre(without)]

"""Plots of campaign results (north/east in metres from the pad, NED world frame)."""

from __future__ import annotations

import hashlib
import json
from collections.abc import Sequence
from datetime import datetime
from typing import TYPE_CHECKING
from importlib import resources
from pathlib import Path

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from ..env.weather import geometric_altitude, read_weather
from ..env.wind import read_wind_profile
from ..files import replacing
from ..ellipse import Ellipse, confidence_ellipse
from .results import Run

if TYPE_CHECKING:  # the tuning imports optax: only where a tuning is drawn
    from ..campaign.tuning import Tuning

_ELLIPSE_COLORS = ("tab:green", "tab:orange", "tab:red", "tab:purple", "tab:brown")
_FAILED_MARKERS = ("x", "+", "1", "s", "D")
RUN_COLORS = ("tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown", "tab:pink", "tab:gray",
               "tab:olive", "tab:cyan")  # fmt: skip


def _shorten(text: str, width: int = 40) -> str:
    """``text`` cut to ``width`` characters with an ellipsis (a legend entry on one line)."""
    return text if len(text) <= width else text[: width - 1] + "…"


SPREAD_RESULTANT = 0.5
"""Below this ratio of the mean wind vector's length to the mean wind speed the directions are called spread
(0 for directions drawn uniformly over 360°, 1 for one fixed direction): no wind arrow is drawn then."""
PROFILE_HEIGHTS = 100
"""Heights, evenly spaced from the pad to the ok flights' median apogee, over which a profile's wind is averaged."""
SURFACE_HEIGHT_M = 10.0
"""The height above the pad [m] a profile's surface wind is given at (the meteorological 10 m wind)."""


def launch_and_wind(run: Run) -> dict | None:
    """The rail azimuth and the wind flown from the file's ``setup`` attribute (its resolved campaign), each
    value taken per flight from ``/inputs`` where dispersed; None for a file without ``setup``.

    ``{"azimuth_deg": circular mean rail azimuth [deg clockwise from north], "source": what wind was flown, in
    words ("3-layer wind", "ERA5/GFS profile of 2023-10-13 12:00Z (file.nc)", "sounding (file.txt)", "measured
    profile (file.csv)"), "wind": None (a profile whose file is not at hand: not the package's own, or changed) or
    {"speed_mps": mean wind speed [m/s], "north_mps", "east_mps": the vector mean of the wind blowing towards
    [m/s], "from_deg": the direction the vector mean blows from, "resultant": its length over the mean speed,
    "spread": resultant < SPREAD_RESULTANT, and for a profile "surface": (speed [m/s], from [deg]) of its nominal
    wind at SURFACE_HEIGHT_M, "turned_deg", "scaled": (lowest, highest) of the turns [deg] and scales [-] drawn per
    flight, "flights": how many}}``. Over the flights and the wind layers (each layer weighted alike; ``constant``
    and ``power_law`` winds at their reference height; a profile over PROFILE_HEIGHTS heights from the pad to the
    median apogee)."""
    if "setup" not in run.attrs:
        return None
    setup = json.loads(run.attrs["setup"])
    config = setup["config"]

    def drawn(name, default):
        """The values of ``name`` per flight: its /inputs column where dispersed, else ``default``."""
        return run.inputs[name].to_numpy(float) if name in run.inputs else np.full(len(run.outputs), float(default))

    def resultant(degrees, lengths):
        """(north, east) of the mean of the vectors of ``lengths`` towards ``degrees`` (clockwise from north)."""
        radians = np.radians(degrees)
        return float(np.mean(lengths * np.cos(radians))), float(np.mean(lengths * np.sin(radians)))

    azimuth_north, azimuth_east = resultant(drawn("launch.azimuth_deg", config["launch"]["azimuth_deg"]), 1.0)
    result = {"azimuth_deg": float(np.degrees(np.arctan2(azimuth_east, azimuth_north)) % 360.0), "wind": None}
    wind, atmosphere = config["environment"]["wind"], config["environment"].get("atmosphere")
    extra = {}
    if atmosphere is not None or wind["model"] == "profile":
        found = _profile(config, setup.get("files", {}))
        result["source"] = found[0]
        if found[1] is None:
            return result
        altitude_m, north_mps, east_mps = found[1]
        if atmosphere is not None:
            turned = drawn("environment.atmosphere.wind_rotation_deg", atmosphere["wind_rotation_deg"])
            scaled = drawn("environment.atmosphere.wind_scale", atmosphere["wind_scale"])
        else:
            turned, scaled = np.zeros(len(run.outputs)), drawn("environment.wind.speed_scale", wind["speed_scale"])
        apogee = run.outputs["apogee_agl_m"].to_numpy(float)[run.ok] if "apogee_agl_m" in run.outputs else []
        top = float(np.nanmedian(apogee)) if np.isfinite(apogee).any() else float(altitude_m[-1])
        heights = np.linspace(0.0, max(top, 0.0), PROFILE_HEIGHTS)
        at_speed, at_from = _speed_from(*(np.interp(heights, altitude_m, c) for c in (north_mps, east_mps)))
        layers = [(scaled * at_speed[j], at_from[j] + turned) for j in range(heights.size)]  # height j in every flight
        surface = _speed_from(*(np.interp(SURFACE_HEIGHT_M, altitude_m, c) for c in (north_mps, east_mps)))
        extra = {"surface": tuple(map(float, surface)), "flights": int(turned.size),
                 "turned_deg": (float(turned.min()), float(turned.max())),
                 "scaled": (float(scaled.min()), float(scaled.max()))}  # fmt: skip
    elif wind["model"] == "layers":
        result["source"] = f"{len(wind['layers'])}-layer wind"
        names = [f"environment.wind.layers.{k}." for k in range(len(wind["layers"]))]
        layers = [(drawn(f"{n}speed_mps", layer["speed_mps"]), drawn(f"{n}from_deg", layer["from_deg"]))
                  for n, layer in zip(names, wind["layers"])]  # fmt: skip
    else:
        result["source"] = ("constant wind" if wind["model"] == "constant"
                            else f"power-law wind, at {wind['reference_height_m']:g} m")  # fmt: skip
        layers = [(drawn("environment.wind.speed_mps", wind["speed_mps"]),
                   drawn("environment.wind.from_deg", wind["from_deg"]))]  # fmt: skip
    speed, from_deg = (np.concatenate(values) for values in zip(*layers))
    north, east = resultant(from_deg + 180.0, speed)
    mean_speed = float(speed.mean())
    ratio = float(np.hypot(north, east) / mean_speed) if mean_speed > 0 else 0.0
    result["wind"] = {"speed_mps": mean_speed, "north_mps": north, "east_mps": east, "resultant": ratio,
                      "from_deg": float(np.degrees(np.arctan2(-east, -north)) % 360.0),
                      "spread": ratio < SPREAD_RESULTANT, **extra}  # fmt: skip
    return result


def _speed_from(north_mps, east_mps):
    """Speed [m/s] and the direction it blows from [deg clockwise from north, 0-360] of a wind (north, east)."""
    return np.hypot(north_mps, east_mps), np.degrees(np.arctan2(-east_mps, -north_mps)) % 360.0


def _profile(config: dict, digests: dict) -> tuple[str, tuple[np.ndarray, np.ndarray, np.ndarray] | None]:
    """What profile wind a resolved campaign ``config`` flew, in words, and its nominal wind: (altitude above the
    pad [m], north, east [m/s]) at its levels, read from the package's data file of that name if it is the one
    flown (its SHA-256 among the set-up's file ``digests``), else None (a user's file, not at hand here)."""
    atmosphere, site = config["environment"].get("atmosphere"), config["site"]
    field, folder = ("environment.atmosphere.file", "weather") if atmosphere else ("environment.wind.file", "wind")
    name = atmosphere["file"] if atmosphere else config["environment"]["wind"]["file"]
    path = resources.files("rocketmc") / "data" / folder / name
    flown = path.is_file() and hashlib.sha256(path.read_bytes()).hexdigest() == digests.get(field)
    if not atmosphere:
        source = f"measured profile ({name})"
        if not flown:
            return source, None
        altitude, speed, from_rad = read_wind_profile(path, site["altitude_m"])
    else:
        time = atmosphere["time_utc"]
        source = f"sounding ({name})" if time is None else f"ERA5/GFS profile ({name})"
        if not flown:
            return source, None
        weather = read_weather(path, site["latitude_deg"], site["longitude_deg"],
                               None if time is None else datetime.fromisoformat(time), atmosphere["grid"])  # fmt: skip
        if weather.time_utc is not None:
            source = f"ERA5/GFS profile of {weather.time_utc:%Y-%m-%d %H:%M}Z ({name})"
        altitude = geometric_altitude(weather.geopotential_height_m) - site["altitude_m"]
        speed, from_rad = weather.speed_mps, weather.from_rad
    return source, (altitude, -speed * np.cos(from_rad), -speed * np.sin(from_rad))


def _wind_note(found: dict) -> str:
    """The legend's line on the wind flown (``launch_and_wind``)."""
    wind, source = found["wind"], found["source"]
    if wind is None:
        return f"wind: {source},\nits file not at hand here: not drawn"
    lines = [f"wind: {source}" + (":" if "surface" in wind else "")]
    if "surface" in wind:
        (low_turn, high_turn), (low_scale, high_scale) = wind["turned_deg"], wind["scaled"]
        surface = wind["surface"]
        lines.append(f"{surface[0]:.1f} m/s from {surface[1]:.0f}° at {SURFACE_HEIGHT_M:g} m")
        varied = [text for text, low, high in ((f"turned {low_turn:+.0f}…{high_turn:+.0f}°", low_turn, high_turn),
                                                (f"scaled ×{low_scale:.2f}…{high_scale:.2f}", low_scale, high_scale))
                  if low != high]  # fmt: skip
        if varied:
            lines.append(f"{', '.join(varied)} over the {wind['flights']} flights")
    if wind["speed_mps"] == 0.0:
        lines.append("calm: no wind")
    elif wind["spread"]:
        lines.append(f"mean wind speed {wind['speed_mps']:.1f} m/s, its direction\nspread over the flights (vector "
                     f"mean {wind['resultant'] * wind['speed_mps']:.1f} m/s): no arrow")  # fmt: skip
    else:
        over = " to apogee" if "surface" in wind else ""
        lines.append(f"mean wind{over} {wind['speed_mps']:.1f} m/s from {wind['from_deg']:.0f}°\n(the arrow: where "
                     "it blows to)")  # fmt: skip
    return "\n".join(lines)


def _draw_launch_and_wind(ax: Axes, run: Run, length_m: float) -> None:
    """The rail azimuth and the mean wind (where it blows to) as arrows of ``length_m`` [m] from the pad, and what
    wind was flown in words (``_wind_note``; no wind arrow when the directions are spread, see
    :data:`SPREAD_RESULTANT`)."""
    found = launch_and_wind(run)
    if found is None:
        return
    arrows = [("tab:gray", found["azimuth_deg"], f"rail {found['azimuth_deg']:.0f}°")]
    wind = found["wind"]
    if wind is not None and wind["speed_mps"] > 0.0 and not wind["spread"]:
        arrows.append(("tab:cyan", (wind["from_deg"] + 180.0) % 360.0, f"wind from {wind['from_deg']:.0f}°"))
    for color, towards_deg, label in arrows:
        tip = (length_m * np.sin(np.radians(towards_deg)), length_m * np.cos(np.radians(towards_deg)))  # (east, north)
        ax.annotate("", xy=tip, xytext=(0.0, 0.0), arrowprops={"arrowstyle": "-|>", "color": color, "linewidth": 2.0},
                    zorder=6)  # fmt: skip
        ax.annotate(label, xy=tip, xytext=(3, 3), textcoords="offset points", color=color, fontsize="small", zorder=6)
    ax.plot([], [], color=arrows[-1][0] if len(arrows) > 1 else "none", linewidth=2.0, label=_wind_note(found))


def _area_label(area_m2: float) -> str:
    """Area in km^2 (m^2 below 0.01 km^2)."""
    if area_m2 >= 1e4:
        return f"{area_m2 / 1e6:.3g} km²"
    return f"{area_m2:.3g} m²"


def plot_impacts(
    run: Run,
    path: str | Path | None = None,
    ax: Axes | None = None,
    levels=(0.5, 0.95, 0.99),
) -> Figure:
    """Impact points of ok realizations with their confidence ellipses.

    East [m] on the x axis, north [m] on the y axis, equal aspect; the pad (origin) and the
    mean impact point are marked, with the rail azimuth and the mean wind from the pad (see
    :func:`launch_and_wind`). Failed realizations that landed are drawn apart, one marker per
    status, and counted in the legend (those without an impact point only counted in the title);
    ellipses are omitted when fewer than 3 ok impact points exist. Draws on ``ax`` if given
    (else on a new figure, without pyplot) and saves to ``path`` (PNG at 150 dpi) if given.
    """
    fig, ax = _figure(ax)
    north, east = run.ok_impacts()
    n_total = len(run.outputs)
    n_ok = int(run.ok.sum())

    _scatter(ax, north, east, "tab:blue", label=f"ok impacts ({n_ok})")
    status = run.outputs["status"].to_numpy()
    for i, code in enumerate(sorted(set(status[~run.ok].tolist()))):
        where = run.has_impact & (status == code)
        if where.any():
            f_north, f_east = run.ok_impacts(where)
            ax.scatter(f_east, f_north, s=22, marker=_FAILED_MARKERS[i % len(_FAILED_MARKERS)], color="k",
                       linewidths=1.0, label=f"status {code} ({int(where.sum())} landed): "
                       f"{_shorten(run.status_codes.get(code, 'unknown'))}", zorder=5)  # fmt: skip
    ax.plot(0.0, 0.0, "k^", markersize=10, label="pad", zorder=4)
    reach = np.hypot(*run.ok_impacts(run.has_impact))
    _draw_launch_and_wind(ax, run, 0.4 * float(reach.max()) if reach.size else 100.0)
    if north.size >= 3:
        for i, level in enumerate(levels):
            ellipse = confidence_ellipse(north, east, level)
            _ellipse(ax, ellipse, _ELLIPSE_COLORS[i % len(_ELLIPSE_COLORS)],
                     f"{100 * level:g} % ellipse, {100 * ellipse.contains(north, east).mean():.1f} % inside")  # fmt: skip
        ax.text(0.01, 0.01, "ellipses: a Gaussian fit to the ok impact points (sample mean and covariance);\n"
                "'inside' is the fraction of ok points each actually holds", transform=ax.transAxes,
                fontsize="small", va="bottom", ha="left", bbox={"facecolor": "white", "alpha": 0.8, "linewidth": 0})
        ax.plot(east.mean(), north.mean(), "kX", markersize=9, label="mean impact", zorder=4)

    title = f"{run.label}: impact points, {n_ok} ok / {n_total}"
    missing = int((~run.ok & ~run.has_impact).sum())
    title += f", seed {run.attrs.get('seed')}"
    if n_ok < n_total:
        title += f"\n{n_total - n_ok} failed (not in the ellipses), {missing} of them without an impact point"
    _finish(fig, ax, title, path)
    return fig


_HISTOGRAMS = (("apogee", "apogee above the pad", "m"), ("impact_distance", "impact distance from the pad", "m"),
               ("landing_speed", "landing speed", "m/s"))  # fmt: skip


def plot_histograms(run: Run, folder: str | Path, bins: int = 30) -> dict[Path, Figure]:
    """Histograms of apogee [m], impact distance from the pad [m] and landing speed [m/s], written to
    ``folder`` as ``apogee.png``, ``impact_distance.png`` and ``landing_speed.png``: the ok flights, and
    stacked on them in grey the failed flights that landed (same bins); N of each in the title and the
    legend, flights without the value (no impact point, NaN) counted in the title. Returns path -> figure."""
    out = run.outputs
    values = {"apogee": out["apogee_agl_m"].to_numpy(float), "landing_speed": out["impact_speed_mps"].to_numpy(float),
              "impact_distance": np.hypot(out["impact_north_m"].to_numpy(float), out["impact_east_m"].to_numpy(float))}
    landed_failed = ~run.ok & run.has_impact
    figures = {}
    for stem, label, unit in _HISTOGRAMS:
        x = values[stem]
        ok, failed = x[run.ok & np.isfinite(x)], x[landed_failed & np.isfinite(x)]
        fig = Figure(figsize=(7.5, 4.5), layout="constrained")
        ax = fig.add_subplot()
        edges = np.histogram_bin_edges(np.concatenate([ok, failed]), bins=bins)
        ax.hist([ok, failed], bins=edges, stacked=True, color=["tab:blue", "0.55"],
                label=[f"ok ({ok.size})", f"failed, landed ({failed.size})"])  # fmt: skip
        title = f"{run.label}: {label}, N = {ok.size + failed.size} of {len(x)} flights"
        if ok.size + failed.size < len(x):
            title += f"\n({len(x) - ok.size - failed.size} without a value: failed in flight or no impact point)"
        ax.set_title(title)
        ax.set_xlabel(f"{label} [{unit}]")
        ax.set_ylabel("flights")
        ax.grid(True, alpha=0.4)
        ax.legend(fontsize="small")
        path = Path(folder) / f"{stem}.png"
        save_figure(fig, path)
        figures[path] = fig
    return figures


def plot_comparison(
    runs: Sequence[tuple[str, Run]],
    path: str | Path | None = None,
    ax: Axes | None = None,
    level: float = 0.95,
) -> Figure:
    """Impact points of the ok realizations of several runs ``(file name, run)``, one colour each,
    with their ``level`` ellipses labelled with campaign name, file name and area.

    Axes, pad, ``ax`` and ``path`` as in :func:`plot_impacts`; each run needs 3 ok impact points.
    """
    fig, ax = _figure(ax)
    for i, (file, run) in enumerate(runs):
        color = RUN_COLORS[i % len(RUN_COLORS)]
        north, east = run.ok_impacts()
        _scatter(ax, north, east, color)
        _ellipse(ax, confidence_ellipse(north, east, level), color,
                 f"{run.label} ({file}): {100 * level:g} % ellipse")  # fmt: skip
    ax.plot(0.0, 0.0, "k^", markersize=10, label="pad", zorder=4)
    _finish(fig, ax, f"Impact points and {100 * level:g} % ellipses of {len(runs)} runs", path)
    return fig


def _figure(ax: Axes | None) -> tuple[Figure, Axes]:
    """``ax`` and its figure, or a new 7.5 in square figure (without pyplot) and its axes."""
    if ax is not None:
        return ax.figure, ax
    fig = Figure(figsize=(7.5, 7.5), layout="constrained")
    return fig, fig.add_subplot()


def _scatter(ax: Axes, north: np.ndarray, east: np.ndarray, color: str, label: str | None = None) -> None:
    """Impact points [m], east on x, fainter the more there are."""
    alpha = float(np.clip(300.0 / max(north.size, 1), 0.15, 0.8))
    ax.scatter(east, north, s=6, color=color, alpha=alpha, linewidths=0, label=label)


def _ellipse(ax: Axes, ellipse: Ellipse, color: str, label: str) -> None:
    """The outline of ``ellipse``, labelled ``label (area)``."""
    b_north, b_east = ellipse.boundary()
    ax.plot(b_east, b_north, color=color, linewidth=1.8, label=f"{label} ({_area_label(ellipse.area_m2)})", zorder=3)


def _finish(fig: Figure, ax: Axes, title: str, path: str | Path | None) -> None:
    """Title, axis labels [m], equal aspect, grid and legend; the figure saved to ``path`` if given."""
    ax.set_title(title)
    ax.set_xlabel("east of pad [m]")
    ax.set_ylabel("north of pad [m]")
    ax.set_aspect("equal", adjustable="datalim")
    ax.grid(True, alpha=0.4)
    legend = ax.legend(loc="best", fontsize="small", framealpha=0.9)
    for handle in legend.legend_handles:  # faint scatter points stay visible in the legend
        handle.set_alpha(1.0)
    if path is not None:
        save_figure(fig, path)


def save_figure(fig: Figure, path: str | Path) -> None:
    """``fig`` at 150 dpi in the format of ``path``'s suffix, written under a temporary name and renamed."""
    with replacing(path) as partial:  # a full disk leaves no half-written figure
        fig.savefig(partial, dpi=150, format=Path(path).suffix.lstrip(".").lower() or "png")


def plot_gains(summary: dict, path: str | Path | None = None) -> Figure:
    """The LQI gain schedule of ``campaign.gains.schedule_summary``: the main pitch and roll gains and the
    spectral radius of the loop as flown (solid; the designed loop's dashed) against speed [m/s], one line per
    design altitude above the pad; saved to ``path`` if given."""
    points = summary["points"]
    panels = [(row, name) for row in ("pitch", "roll") for name in points[0][row]] + [(None, "flown_spectral_radius")]
    fig = Figure(figsize=(13.0, 6.5), layout="constrained")
    axes = fig.subplots(2, 4, sharex=True).ravel()
    for altitude in sorted({p["altitude_agl_m"] for p in points}):
        at = [p for p in points if p["altitude_agl_m"] == altitude]
        speeds = [p["speed_mps"] for p in at]
        for ax, (row, name) in zip(axes, panels):
            line, = ax.plot(speeds, [p[name] if row is None else p[row][name] for p in at], marker=".",
                            label=f"{altitude:g} m")  # fmt: skip
        axes[len(panels) - 1].plot(speeds, [p["spectral_radius"] for p in at], ls="--", color=line.get_color())
    for ax, (row, name) in zip(axes, panels):
        ax.set_title("spectral radius, flown (designed dashed)" if row is None else f"{row} {name}")
        ax.grid(True, alpha=0.4)
    for ax in axes[4:]:
        ax.set_xlabel("speed [m/s]")
    axes[0].legend(title="above the pad", fontsize="small")
    fig.suptitle(f"{summary['campaign']}: LQI gains ({summary['aero_model']} aerodynamics, "
                 f"{summary['discretisation']}, dt {summary['dt_s']:g} s)")  # fmt: skip
    if path is not None:
        save_figure(fig, path)
    return fig


def plot_aero_curves(curves: list[dict], title: str, path: str | Path | None = None) -> Figure:
    """Against Mach (``campaign.checks.aero_curves``): the zero-lift axial coefficient CA0 (the drag coefficient at
    α = 0), the normal-force slope CNα [1/rad], and the centre of pressure with the centre of mass at liftoff and at
    burnout [m from the nose tip]; saved to ``path`` if given."""
    mach = [c["mach"] for c in curves]
    fig = Figure(figsize=(7.0, 8.0), layout="constrained")
    ax_drag, ax_lift, ax_cp = fig.subplots(3, 1, sharex=True)
    ax_drag.plot(mach, [c["coefficients_per_rad"]["CA0"] for c in curves])
    ax_drag.set_ylabel("CA0 (CD at α = 0)")
    ax_lift.plot(mach, [c["coefficients_per_rad"]["CNa"] for c in curves])
    ax_lift.set_ylabel("CNα [1/rad]")
    ax_cp.plot(mach, [c["center_of_pressure_m"] for c in curves], label="centre of pressure")
    for when, x_m in curves[0]["center_of_mass_m"].items():
        ax_cp.axhline(x_m, ls="--", color=RUN_COLORS[1 if when == "liftoff" else 2], label=f"centre of mass at {when}")
    ax_cp.set_ylabel("from the nose tip [m]")
    ax_cp.invert_yaxis()  # the nose up, as the rocket stands
    ax_cp.legend(fontsize="small")
    ax_cp.set_xlabel("Mach")
    for ax in (ax_drag, ax_lift, ax_cp):
        ax.grid(True, alpha=0.4)
    first = curves[0]
    fig.suptitle(f"{title}\n{first['model']} aerodynamics at {first['altitude_m']:g} m, reference "
                 f"{first['reference_area_m2'] * 1e4:.4g} cm², d {first['reference_length_m']:g} m", fontsize="medium")  # fmt: skip
    if path is not None:
        save_figure(fig, path)
    return fig


def plot_tuning(tuning: Tuning, held_out: dict[str, dict], path: str | Path) -> Path:
    """``rocketmc tune``'s figure: the training objective against the step, the held-out values (``held_out``: label ->
    ``campaign.tuning.evaluate``'s) as lines, and each tuned number relative to its start, to ``path``."""
    from ..campaign.tuning import OBJECTIVES

    figure = Figure(figsize=(9, 4.2), layout="constrained")
    left, right = figure.subplots(1, 2)
    steps = np.arange(len(tuning.objective))
    left.plot(steps, tuning.objective, "o-", color="k", ms=3, label=f"training ({tuning.train} flights)")
    for (label, result), color in zip(held_out.items(), ("tab:gray", "tab:blue", "tab:green")):
        left.axhline(result["value"], color=color, ls="--", label=f"held out: {label}")
    left.set(xlabel="Adam step", ylabel=OBJECTIVES[tuning.objective_name], title=tuning.objective_name)
    left.legend(fontsize=8)
    start = np.where(tuning.values[0] != 0.0, tuning.values[0], 1.0)
    for k, name in enumerate(tuning.paths):
        right.plot(steps, tuning.values[:, k] / start[k], label=name.removeprefix("gnc.guidance."))
    right.axvline(tuning.best, color="k", lw=0.8, ls=":")
    right.set(xlabel="Adam step", ylabel="value / starting value (a start of 0: the value)", title="tuned numbers")
    right.legend(fontsize=8)
    save_figure(figure, path)
    return Path(path)

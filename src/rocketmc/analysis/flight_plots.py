"""Figures of one flight's time series (``rocketmc fly --plot DIR``): the 3-D path, altitude and speed, the angles
of attack and the static margin against time, and with air brakes their deployment and predicted apogee
(``AIRBRAKE_FIGURE``), each sample a period start of the flight's own periods."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from ..campaign.flights import FlightRecord
from .flight_record import ascent, events
from .plots import save_figure

FIGURES = ("path_3d.png", "altitude_speed.png", "angles_of_attack.png", "stability_margin.png")
AIRBRAKE_FIGURE = "airbrakes.png"
_EVENT_COLORS = {"rail exit": "tab:gray", "burnout": "tab:red", "apogee": "tab:green", "impact": "black"}
_CHUTE_COLORS = ("tab:purple", "tab:brown", "tab:pink", "tab:olive")


def _save(fig: Figure, path: Path) -> None:
    fig.tight_layout()
    save_figure(fig, path)


def _events(axes, record: FlightRecord, until: float | None = None) -> None:
    """Dashed vertical lines at the events (up to ``until`` [s]), labelled in the first axes' legend."""
    chute_colors = iter(_CHUTE_COLORS * len(record.campaign.config.rocket.parachutes))
    for name, t in events(record):
        color = _EVENT_COLORS.get(name) or next(chute_colors)  # the parachutes' in the order they deploy
        if until is not None and t > until:
            continue
        for k, ax in enumerate(axes):
            ax.axvline(t, color=color, linestyle="--", linewidth=0.8, label=f"{name} ({t:.2f} s)" if k == 0 else None)


def _finish(axes, record: FlightRecord, until: float | None = None, loc: str = "upper right") -> None:
    """The events (``_events``), a legend and a light grid on each of the time-series ``axes``."""
    _events(axes, record, until)
    for ax in axes:
        ax.legend(fontsize="small", loc=loc)
        ax.grid(alpha=0.3)


def plot_flight(record: FlightRecord, directory: str | Path) -> list[Path]:
    """Write the ``FIGURES`` of ``record`` (and ``AIRBRAKE_FIGURE`` with air brakes) in ``directory`` (created if need
    be); returns their paths."""
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    paths = [directory / name for name in FIGURES]
    s, m = record.series, record.summary
    t = s["time"].to_numpy()

    fig = Figure(figsize=(8.0, 7.0))
    ax = fig.add_subplot(projection="3d")
    phases = list(dict.fromkeys(s["phase"]))
    for phase in phases:  # each phase its colour, joined to the next one's first sample
        idx = np.nonzero(s["phase"].to_numpy() == phase)[0]
        idx = np.r_[idx, idx[-1] + 1] if idx[-1] + 1 < len(s) else idx
        ax.plot(s["east"].to_numpy()[idx], s["north"].to_numpy()[idx], s["altitude"].to_numpy()[idx], linewidth=1.5,
                label=phase)  # fmt: skip
    ax.plot(s["east"], s["north"], 0.0 * t, color="0.7", linewidth=0.8, label="ground track")
    ax.scatter([0.0], [0.0], [0.0], color="black", marker="^", s=50, label="pad")
    if not np.isnan(m["apogee_time_s"]):
        ax.scatter([m["apogee_east_m"]], [m["apogee_north_m"]], [m["apogee_agl_m"]], color="tab:green", s=30,
                   label=f"apogee {m['apogee_agl_m']:.0f} m")  # fmt: skip
    if not np.isnan(m["impact_time_s"]):
        ax.scatter([m["impact_east_m"]], [m["impact_north_m"]], [0.0], color="black", marker="x", s=50, label="impact")
    ax.set_xlabel("east of the pad [m]")
    ax.set_ylabel("north of the pad [m]")
    ax.set_zlabel("altitude above the pad [m]")
    ax.set_title(f"{record.label}: flight path")
    ax.legend(fontsize="small", loc="upper left")
    _save(fig, paths[0])

    fig = Figure(figsize=(9.0, 7.5))
    ax_alt, ax_speed = fig.subplots(2, 1, sharex=True)
    ax_alt.plot(t, s["altitude"], color="tab:blue", label="altitude above the pad")
    ax_alt.set_ylabel("altitude above the pad [m]")
    ax_speed.plot(t, s["speed"], color="tab:blue", label="speed over ground")
    ax_speed.plot(t, s["airspeed"], color="tab:orange", linewidth=0.8, label="airspeed")
    ax_speed.plot(t, -s["v_down"], color="tab:green", linewidth=0.8, label="vertical speed (up)")
    ax_speed.set_ylabel("speed [m/s]")
    ax_speed.set_xlabel("time since the start on the rail [s]")
    _finish((ax_alt, ax_speed), record)
    ax_alt.set_title(f"{record.label}: altitude and speed")
    _save(fig, paths[1])

    up = shown = ascent(record)  # off the rail (slow, so large angles in a wind) and before the canopies
    end = m["apogee_time_s"]
    fig = Figure(figsize=(9.0, 7.5))
    ax_angles, ax_mach = fig.subplots(2, 1, sharex=True)
    ax_angles.plot(shown["time"], shown["alpha"], label="angle of attack α")
    ax_angles.plot(shown["time"], shown["beta"], label="sideslip β")
    ax_angles.plot(shown["time"], shown["total_alpha"], color="black", linewidth=0.8, label="total angle of attack")
    ax_angles.set_ylabel("angle [deg]")
    ax_mach.plot(shown["time"], shown["mach"], color="tab:blue", label="Mach number")
    ax_mach.set_ylabel("Mach number [-]")
    ax_q = ax_mach.twinx()
    ax_q.plot(shown["time"], shown["dynamic_pressure"] / 1000.0, color="tab:red", linewidth=0.8, label="dynamic pressure")
    ax_q.set_ylabel("dynamic pressure [kPa]", color="tab:red")
    ax_mach.set_xlabel("time since the start on the rail [s]")
    _finish((ax_angles, ax_mach), record, end)
    lines = ax_mach.get_legend_handles_labels()[0] + ax_q.get_legend_handles_labels()[0]
    ax_mach.legend(lines, [h.get_label() for h in lines], fontsize="small", loc="upper right")  # with the twin's line
    ax_angles.set_title(f"{record.label}: angles of attack, rail exit to apogee\n"
                        "(air-relative velocity: mean wind and gust)")  # fmt: skip
    _save(fig, paths[2])

    fig = Figure(figsize=(9.0, 7.5))
    ax_margin, ax_position = fig.subplots(2, 1, sharex=True)
    ax_margin.plot(up["time"], up["static_margin"], color="tab:blue", label="static margin (CP − CG)/d")
    ax_margin.set_ylabel("static margin [calibers]")
    ax_position.plot(up["time"], up["cp"], color="tab:red", label="centre of pressure (Mach, small α)")
    ax_position.plot(up["time"], up["cg"], color="tab:blue", label="centre of mass")
    ax_position.set_ylabel("distance from the nose tip [m]")
    ax_position.invert_yaxis()  # the nose on top, the tail below
    ax_position.set_xlabel("time since the start on the rail [s]")
    _finish((ax_margin, ax_position), record, end, loc="lower right")
    ax_margin.set_title(f"{record.label}: static stability, rail exit to apogee")
    _save(fig, paths[3])
    if "airbrake_deployment" in s:
        paths.append(_plot_airbrakes(record, directory / AIRBRAKE_FIGURE))
    return paths


def _plot_airbrakes(record: FlightRecord, path: Path) -> Path:
    """The air brakes to apogee: altitude, the software's predicted apogee and the target (the reference-trajectory PI:
    the climb rate and the chosen reference's); deployment and command."""
    up, end = ascent(record), record.summary["apogee_time_s"]
    target = record.campaign.config.airbrakes.target_apogee_m
    fig = Figure(figsize=(9.0, 7.5))
    ax_height, ax_deployment = fig.subplots(2, 1, sharex=True)
    if "reference_climb" in up:
        ax_height.plot(up["time"], -up["v_down"], color="tab:blue", label="climb rate")
        ax_height.plot(up["time"], up["reference_climb"], color="tab:orange", label=f"the chosen reference's, to {target:.0f} m")
        ax_height.set_ylabel("climb rate [m/s]")
    else:
        ax_height.plot(up["time"], up["altitude"], color="tab:blue", label="altitude above the pad")
        ax_height.plot(up["time"], up["predicted_apogee"], color="tab:orange", label="predicted apogee (while allowed)")
        ax_height.axhline(target, color="black", linewidth=0.8, label=f"target {target:.0f} m")
        ax_height.set_ylabel("height above the pad [m]")
    ax_deployment.plot(up["time"], up["airbrake_deployment"], color="tab:blue", label="deployment")
    ax_deployment.plot(up["time"], up["airbrake_command"], color="tab:orange", linewidth=0.8, label="command")
    ax_deployment.set_ylabel("deployment [0 … 1]")
    ax_deployment.set_xlabel("time since the start on the rail [s]")
    _finish((ax_height, ax_deployment), record, end, loc="lower right")
    ax_height.set_title(f"{record.label}: air brakes, rail exit to apogee")
    _save(fig, path)
    return path

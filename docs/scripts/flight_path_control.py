"""The thesis's Fig. 7: the flight-path angle of the Lynx under a constant 10 m/s wind, controller off, on
from 1 s and on from 3.5 s after liftoff (perfect navigation), and the canard deflections it flew.

    python docs/scripts/flight_path_control.py [--out docs/figures/flight_path_control.png] [--aero-model MODEL]

The three ballistic campaigns of the thesis's Monte Carlo (campaigns/lynx_ballistic_ctrl_*.toml), flown
nominal: their wind replaced by a constant 10 m/s from the launch azimuth (a headwind, which the rocket
weathercocks into), no turbulence, no dispersions. Prints the flight-path angle at a few times, against the
guidance's reference, and the deflections' largest value.
"""

from __future__ import annotations

import argparse
import tomllib
from pathlib import Path

import jax
import matplotlib.pyplot as plt
import numpy as np

from rocketmc.campaign import campaign_from_dict, with_overrides
from rocketmc.campaign.model import nominal_params
from rocketmc.campaign.runner import sim_settings
from rocketmc.gnc.guidance import reference_direction
from rocketmc.sim.flight import fly

CASES = {"controller off": "lynx_ballistic_ctrl_off", "from 1 s": "lynx_ballistic_ctrl_1s",
         "from 3.5 s": "lynx_ballistic_ctrl_3p5s"}  # fmt: skip
WIND_MPS = 10.0
DURATION_S = 20.0
SHOWN_TIMES_S = (1.0, 2.0, 3.5, 5.0, 7.5, 10.0, 12.0)


def steady_wind_campaign(path: Path, aero_model: str | None):
    """The campaign of ``path`` with a constant wind from the launch azimuth, no turbulence, no dispersions."""
    raw = tomllib.loads(path.read_text())
    raw["environment"] = {"wind": {"model": "constant", "speed_mps": WIND_MPS, "from_deg": raw["launch"]["azimuth_deg"]}}
    raw["dispersions"] = {}
    campaign = campaign_from_dict(raw, path.parent, path.read_text())
    return campaign if aero_model is None else with_overrides(campaign, aero_model=aero_model)


def flight(campaign) -> dict[str, np.ndarray]:
    """Time [s], flight-path angle [deg], the reference's [deg] and the fins' deflections (n, 4) [deg]."""
    p, settings = nominal_params(campaign), sim_settings(campaign)
    _, traj = jax.jit(lambda p: fly(p, settings, int(round(DURATION_S / settings.control_dt_s))))(p)
    v = traj.body.v_n
    t = np.asarray(traj.t)
    horizontal = np.hypot(np.asarray(v.x), np.asarray(v.y))
    gamma = np.degrees(np.arctan2(-np.asarray(v.z), horizontal))
    out = {"t": t, "gamma_deg": np.where(np.hypot(horizontal, np.asarray(v.z)) > 1.0, gamma, np.nan)}  # undefined at rest
    if traj.gnc is not None:
        since_liftoff = t - np.asarray(traj.gnc.liftoff_time)
        d = reference_direction(p.gnc.guidance, None, since_liftoff)
        out["reference_deg"] = np.where(np.isfinite(since_liftoff), np.degrees(np.arcsin(-np.asarray(d.z))), np.nan)
        offset = np.asarray(p.gnc.servo.offset_rad)
        out["deflections_deg"] = np.degrees(np.asarray(traj.gnc.servo.deflection_rad) + offset)
        out["window_s"] = float(p.gnc.guidance.window_start_s), float(p.gnc.guidance.window_end_s)
        out["liftoff_s"] = float(np.asarray(traj.gnc.liftoff_time)[-1])
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--campaigns", default="campaigns", help="folder of the lynx_ballistic_ctrl_* campaigns")
    parser.add_argument("--out", default="docs/figures/flight_path_control.png")
    parser.add_argument("--aero-model", choices=("linear", "simplified", "interpolated"))
    args = parser.parse_args()
    flights = {label: flight(steady_wind_campaign(Path(args.campaigns) / f"{name}.toml", args.aero_model))
               for label, name in CASES.items()}  # fmt: skip
    model = args.aero_model or "linear"
    print(f"Lynx, constant {WIND_MPS:g} m/s headwind, {model} aerodynamics: flight-path angle [deg] at t [s]")
    print("case              " + "".join(f"{t:>7g}" for t in SHOWN_TIMES_S) + "   max |δ| [deg]")
    for label, f in flights.items():
        at = [float(np.interp(t, f["t"], f["gamma_deg"])) for t in SHOWN_TIMES_S]
        largest = f"{np.abs(f['deflections_deg']).max():.2f}" if "deflections_deg" in f else "-"
        print(f"{label:<18}" + "".join(f"{g:>7.2f}" for g in at) + f"   {largest:>8}")
    reference = flights["from 1 s"]
    at = [float(np.interp(t, reference["t"], reference["reference_deg"])) for t in SHOWN_TIMES_S]
    print(f"{'reference':<18}" + "".join(f"{g:>7.2f}" for g in at))

    fig, axes = plt.subplots(1, 3, figsize=(15, 4.2), constrained_layout=True)
    for label, f in flights.items():
        axes[0].plot(f["t"], f["gamma_deg"], label=label)
    axes[0].plot(reference["t"], reference["reference_deg"], "k:", lw=1, label="reference")
    axes[0].set_ylim(40, 90)
    axes[0].set_ylabel("flight-path angle γ [°]")
    for ax, label in zip(axes[1:], ("from 1 s", "from 3.5 s")):
        f = flights[label]
        for i in range(f["deflections_deg"].shape[1]):
            ax.plot(f["t"], f["deflections_deg"][:, i], lw=1, label=f"δ{i + 1}")
        for edge in f["window_s"]:
            ax.axvline(f["liftoff_s"] + edge, color="0.7", lw=0.8)
        ax.set_ylabel(f"canard deflection [°], controller {label}")
        ax.set_xlim(0, 12)
    for ax in axes:
        ax.set_xlabel("time [s] (ignition at 0.5 s)")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle(f"Lynx, constant {WIND_MPS:g} m/s headwind, {model} aerodynamics, perfect navigation (thesis Fig. 7)")
    fig.savefig(args.out, dpi=120)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()

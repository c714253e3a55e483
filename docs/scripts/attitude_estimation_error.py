"""The thesis's Fig. 3: the attitude estimation error during a flight, with the MEKF's own 3σ.

    python docs/scripts/attitude_estimation_error.py [--out docs/figures/attitude_estimation_error.png] [--realization 0]

Realization I of the full-GNC ballistic case from 1 s (campaigns/lynx_ballistic_gnc_1s.toml: its drawn wind and
turbulence, the thesis's sensors and filter tuning), flown 20 s with the filters' state and the true body recorded.
The error δϑ is the body-frame rotation from the estimate to the truth (``gnc.attitude_filter.attitude_error_b``),
each component against ±3 sqrt(P) of the filter. Prints its RMS and largest value over the window and the ascent.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import jax
import matplotlib.pyplot as plt
import numpy as np

from rocketmc.campaign import load_campaign
from rocketmc.campaign.runner import realization_params, sim_settings
from rocketmc.gnc.attitude_filter import attitude_error_b
from rocketmc.sim.flight import fly

CAMPAIGN = Path(__file__).parents[2] / "campaigns" / "lynx_ballistic_gnc_1s.toml"
DURATION_S = 20.0  # past apogee (~19 s)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=str(Path(__file__).parents[1] / "figures" / "attitude_estimation_error.png"))
    parser.add_argument("--realization", type=int, default=0)
    args = parser.parse_args()
    campaign = load_campaign(CAMPAIGN)
    settings = sim_settings(campaign)
    params, _ = realization_params(campaign, jax.random.key(campaign.config.seed), np.uint32(args.realization))
    record = lambda s: (s.t, s.gnc.navigation.attitude, s.gnc.liftoff_time, s.body.q_nb, s.events.apogee_time)  # noqa: E731
    n = int(round(DURATION_S / settings.control_dt_s))
    _, (t, attitude, liftoff, q_true, apogee) = jax.jit(lambda p: fly(p, settings, n, record=record))(params)
    # the state recorded after period k holds the filters' solution at its start; the body after period k - 1 is the truth then
    t = np.asarray(t)[:-1]
    error = np.degrees(np.stack(attitude_error_b(jax.tree_util.tree_map(lambda x: x[1:], attitude.q_nb),
                                                 jax.tree_util.tree_map(lambda x: x[:-1], q_true))))  # fmt: skip
    sigma = np.degrees(np.sqrt(np.stack([np.asarray(attitude.cov)[1:, i, i] for i in range(3)])))
    liftoff, apogee = float(np.asarray(liftoff)[-1]), float(np.asarray(apogee)[-1])
    g = params.gnc.guidance
    window = (t - liftoff >= float(g.window_start_s)) & (t - liftoff < float(g.window_end_s))
    norm = np.linalg.norm(error, axis=0)
    ascent = (t >= liftoff) & (t < apogee)
    print(f"realization {args.realization}: |δϑ| over the window RMS {np.sqrt(np.mean(norm[window] ** 2)):.2f}°, "
          f"max {norm[window].max():.2f}°; over the ascent RMS {np.sqrt(np.mean(norm[ascent] ** 2)):.2f}°, max {norm[ascent].max():.2f}°")

    fig, axes = plt.subplots(4, 1, figsize=(8, 9), sharex=True, constrained_layout=True)
    for i, (ax, axis) in enumerate(zip(axes, ("x (roll)", "y (pitch)", "z (yaw)"))):
        ax.plot(t - liftoff, error[i], lw=1.0, label="δϑ")
        ax.fill_between(t - liftoff, -3 * sigma[i], 3 * sigma[i], color="0.85", label="±3σ of the filter (the grey fills the panel: its σ is far larger)")
        ax.set_ylim(-4 * np.abs(error[i][ascent]).max() - 0.5, 4 * np.abs(error[i][ascent]).max() + 0.5)
        ax.set_ylabel(f"δϑ {axis} [deg]")
    axes[3].plot(t - liftoff, norm, color="k", lw=1.0)
    axes[3].set_ylabel("|δϑ| [deg]")
    axes[3].set_xlabel("time since liftoff [s]")
    for ax in axes:
        ax.axvspan(float(g.window_start_s), float(g.window_end_s), color="tab:green", alpha=0.08)
        ax.axvline(apogee - liftoff, color="0.5", ls=":", lw=0.8)
        ax.grid(alpha=0.3)
    axes[0].legend(loc="upper left", fontsize=8)
    axes[0].set_title(f"Attitude estimation error, MEKF (thesis's tuning), {campaign.config.name} realization "
                      f"{args.realization}\ncontrol window shaded, apogee dotted; the roll axis, nearly along the field, "
                      "is unobservable", fontsize=9)  # fmt: skip
    fig.savefig(args.out, dpi=120)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()

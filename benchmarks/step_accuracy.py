"""Accuracy of the campaign's steps: the same realizations flown with its steps and with a reference whose RK4 step
is ``--factor`` times finer (control-period substeps).

The reference ``periods`` (default) also flies every period at ``control_dt_s``, no long descent periods: a tenth of
the campaign's step everywhere. Its turbulence then draws one noise row per 20 ms period under canopy where the
campaign draws one per long period, so with turbulence the two fly different gusts under canopy (the same statistics,
another realization): ``--calm`` sets every realization's turbulence severity to none, so the differences are the
integration's; the reference ``substeps`` keeps the campaign's periods and refines only the RK4 step (the same gusts).

    python benchmarks/step_accuracy.py [--campaign campaigns/lynx_nominal.toml] [--n 200] [--factor 10]
                                       [--reference periods|substeps] [--calm]
"""

from __future__ import annotations

import argparse

import numpy as np

from rocketmc.campaign import load_campaign, run_chunks, with_overrides


def outputs(campaign) -> dict:
    chunks = list(run_chunks(campaign))[1:]
    return {k: np.concatenate([c.outputs[k] for c in chunks]) for k in chunks[0].outputs}


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--campaign", default="campaigns/lynx_nominal.toml")
    parser.add_argument("--n", type=int, default=200)
    parser.add_argument("--factor", type=int, default=10, help="RK4 substeps of the reference per campaign substep")
    parser.add_argument("--reference", choices=("periods", "substeps"), default="periods")
    parser.add_argument("--calm", action="store_true", help="no turbulence in any realization")
    args = parser.parse_args()
    campaign = load_campaign(args.campaign)
    calm = {}
    if args.calm and campaign.config.environment.turbulence is not None:
        calm = {"environment.turbulence.severity": 0.0, "dispersions.environment.turbulence.severity": None}
    campaign = with_overrides(campaign, n_realizations=args.n, values=calm)
    sim = campaign.config.simulation
    finer = {"simulation.substeps": args.factor * sim.substeps}
    if args.reference == "periods":
        finer["simulation.descent_dt_s"] = sim.control_dt_s
    fine = with_overrides(campaign, values=finer)
    fine_sim = fine.config.simulation
    a, b = outputs(campaign), outputs(fine)
    print(f"{campaign.config.name}, N={args.n}{', calm' if args.calm else ''}: campaign steps (substeps "
          f"{sim.substeps}, descent {sim.descent_dt_s} s) vs reference (substeps {fine_sim.substeps}, descent "
          f"{fine_sim.descent_dt_s} s)")  # fmt: skip
    miss = np.hypot(a["impact_north_m"] - b["impact_north_m"], a["impact_east_m"] - b["impact_east_m"])
    print(f"  impact point difference: median {np.nanmedian(miss):.3f} m, max {np.nanmax(miss):.3f} m")
    apogee = np.abs(a["apogee_agl_m"] / b["apogee_agl_m"] - 1.0)
    print(f"  apogee relative difference: median {np.nanmedian(apogee):.2e}, max {np.nanmax(apogee):.2e}")
    for name in ("apogee_time_s", "impact_time_s", "impact_speed_mps", "rail_exit_speed_mps"):
        d = np.abs(a[name] - b[name])
        print(f"  {name:24s} |difference| median {np.nanmedian(d):.4g}, max {np.nanmax(d):.4g}")


if __name__ == "__main__":
    main()

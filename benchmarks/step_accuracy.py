"""Accuracy of the campaign's steps: the same realizations flown with its steps and with a reference whose RK4 step
is ``--factor`` times finer (control-period substeps).

The reference ``periods`` (default) also flies every period at ``control_dt_s`` (20 ms), no longer open-loop
(``open_loop_dt_s``) or descent periods: a tenth of the 20 ms step everywhere. Its turbulence then draws one noise row
per 20 ms period where the campaign draws one per longer period, so with turbulence the two fly different gusts (the
same statistics, another realization): ``--calm`` sets every realization's turbulence severity to none, so the
differences are the integration's; the reference ``substeps`` keeps the campaign's periods and refines only the RK4
step (the same gusts). ``--set`` changes the measured flights' campaign values, not the reference's.

    python benchmarks/step_accuracy.py [--campaign campaigns/lynx_nominal.toml] [--n 200] [--factor 10]
                                       [--reference periods|substeps] [--calm] [--set KEY=VALUE ...]
"""

from __future__ import annotations

import argparse
import json

import numpy as np

from rocketmc.campaign import load_campaign, run_chunks, with_overrides


def outputs(campaign) -> dict:
    chunks = list(run_chunks(campaign))[1:]
    return {k: np.concatenate([c.outputs[k] for c in chunks]) for k in chunks[0].outputs}


def _steps(campaign) -> str:
    sim = campaign.config.simulation
    return (f"periods {sim.control_dt_s:g} s, open loop {sim.open_loop_dt_s or sim.control_dt_s:g} s, "
            f"6-DOF descent up to {sim.descent_dt_s:g} s{', then a point mass up to 5 s' if sim.point_mass_descent else ''}, "
            f"{sim.substeps} RK4 steps each")


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--campaign", default="campaigns/lynx_nominal.toml")
    parser.add_argument("--n", type=int, default=200)
    parser.add_argument("--factor", type=int, default=10, help="RK4 substeps of the reference per campaign substep")
    parser.add_argument("--reference", choices=("periods", "substeps"), default="periods")
    parser.add_argument("--calm", action="store_true", help="no turbulence in any realization")
    parser.add_argument("--set", nargs="*", default=[], metavar="KEY=VALUE",
                        help="campaign values (JSON) of the flights measured, not the reference's, e.g. "
                             "simulation.open_loop_dt_s=0.04")
    args = parser.parse_args()
    campaign = load_campaign(args.campaign)
    calm = {}
    if args.calm and campaign.config.environment.turbulence is not None:
        calm = {"environment.turbulence.severity": 0.0, "dispersions.environment.turbulence.severity": None}
    campaign = with_overrides(campaign, n_realizations=args.n, values=calm)
    sim = campaign.config.simulation
    finer = {"simulation.substeps": args.factor * sim.substeps}
    if args.reference == "periods":
        finer["simulation.descent_dt_s"] = finer["simulation.open_loop_dt_s"] = sim.control_dt_s
        finer["simulation.point_mass_descent"] = False
    fine = with_overrides(campaign, values=finer)
    measured = {key: json.loads(value) for key, value in (item.split("=", 1) for item in args.set)}
    campaign = with_overrides(campaign, values=measured)
    a, b = outputs(campaign), outputs(fine)
    print(f"{campaign.config.name}, N={args.n}{', calm' if args.calm else ''}: campaign ({_steps(campaign)}) vs "
          f"reference ({_steps(fine)})")
    miss = np.hypot(a["impact_north_m"] - b["impact_north_m"], a["impact_east_m"] - b["impact_east_m"])
    print(f"  impact point difference: median {np.nanmedian(miss):.3f} m, max {np.nanmax(miss):.3f} m (realization "
          f"{np.nanargmax(miss)})")
    apogee = np.abs(a["apogee_agl_m"] / b["apogee_agl_m"] - 1.0)
    print(f"  apogee relative difference: median {np.nanmedian(apogee):.2e}, max {np.nanmax(apogee):.2e}")
    for name in ("apogee_time_s", "impact_time_s", "impact_speed_mps", "rail_exit_speed_mps"):
        d = np.abs(a[name] - b[name])
        print(f"  {name:24s} |difference| median {np.nanmedian(d):.4g}, max {np.nanmax(d):.4g}")


if __name__ == "__main__":
    main()

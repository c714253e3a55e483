"""Accuracy of the default steps: the same realizations flown with the campaign's steps and with a
reference of 4× finer control-period substeps and no long descent steps.

    python benchmarks/step_accuracy.py [--campaign campaigns/lynx_nominal.toml] [--n 200]
"""

from __future__ import annotations

import argparse
import dataclasses

import numpy as np

from rocketmc.campaign import load_campaign, run_chunks, with_overrides


def outputs(campaign) -> dict:
    chunks = list(run_chunks(campaign))[1:]
    return {k: np.concatenate([c.outputs[k] for c in chunks]) for k in chunks[0].outputs}


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--campaign", default="campaigns/lynx_nominal.toml")
    parser.add_argument("--n", type=int, default=200)
    args = parser.parse_args()
    campaign = with_overrides(load_campaign(args.campaign), n_realizations=args.n)
    sim = campaign.config.simulation
    fine_sim = sim.model_copy(update={"substeps": 4 * sim.substeps, "descent_dt_s": sim.control_dt_s})
    fine = dataclasses.replace(campaign, config=campaign.config.model_copy(update={"simulation": fine_sim}))
    a, b = outputs(campaign), outputs(fine)
    print(f"{campaign.config.name}, N={args.n}: default (substeps {sim.substeps}, descent {sim.descent_dt_s} s) "
          f"vs reference (substeps {fine_sim.substeps}, descent {fine_sim.descent_dt_s} s)")  # fmt: skip
    miss = np.hypot(a["impact_north_m"] - b["impact_north_m"], a["impact_east_m"] - b["impact_east_m"])
    print(f"  impact point difference: median {np.median(miss):.3f} m, max {np.max(miss):.3f} m")
    for name in ("apogee_agl_m", "apogee_time_s", "impact_time_s", "rail_exit_speed_mps"):
        d = np.abs(a[name] - b[name])
        print(f"  {name:24s} max |difference| {np.nanmax(d):.4g}")


if __name__ == "__main__":
    main()

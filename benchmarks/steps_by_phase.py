"""Control periods per flight by phase: the ascent (to apogee), periods of ``control_dt_s`` after apogee (canopy
openings and their settling, wind-layer crossings) and the long steady-descent periods; medians over realizations.

    python benchmarks/steps_by_phase.py [--campaign campaigns/lynx_nominal.toml] [--n 32]
"""

from __future__ import annotations

import argparse
import math

import jax
import jax.numpy as jnp
import numpy as np

from rocketmc.campaign import load_campaign
from rocketmc.campaign.runner import realization_params, sim_settings
from rocketmc.sim.flight import fly
from rocketmc.sim.state import done


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--campaign", default="campaigns/lynx_nominal.toml")
    parser.add_argument("--n", type=int, default=32)
    args = parser.parse_args()
    campaign = load_campaign(args.campaign)
    settings = sim_settings(campaign)
    master = jax.random.key(campaign.config.seed)
    n_periods = math.ceil(settings.max_time_s / settings.control_dt_s)

    def periods(index):
        p, _ = realization_params(campaign, master, index)
        record = lambda s: (s.t, jnp.isfinite(s.events.apogee_time), done(s))  # noqa: E731
        return fly(p, settings, n_periods, record=record)[1]

    t, past_apogee, landed = map(np.asarray, jax.jit(jax.vmap(periods))(jnp.arange(args.n, dtype=jnp.uint32)))
    length = np.diff(t, axis=1, prepend=0.0)
    flying = ~np.concatenate([np.zeros((args.n, 1), bool), landed[:, :-1]], axis=1)  # the period that lands counts
    ascent, descent = flying & ~past_apogee, flying & past_apogee
    short = np.isclose(length, settings.control_dt_s)
    rows = {"ascent": ascent, f"after apogee, {settings.control_dt_s:g} s": descent & short,
            "after apogee, longer": descent & ~short}  # fmt: skip
    print(f"{campaign.config.name}, {args.n} realizations: median periods per flight {np.median(flying.sum(1)):.0f}")
    for name, mask in rows.items():
        seconds = np.where(mask, length, 0.0).sum(1)
        print(f"  {name:28s} {np.median(mask.sum(1)):6.0f} periods, {np.median(seconds):6.1f} s of flight")


if __name__ == "__main__":
    main()

"""Cost of the aerodynamic models on a whole vmapped campaign, measured in one run.

    python benchmarks/aero_models.py [--campaign campaigns/lynx_nominal.toml] [--n 1000]
                                     [--repeats 2] [--json FILE] [--max-ratio 1.5]

Flies the same N realizations with each model (``interpolated``: tables, ``simplified``: their
linearisation, ``linear``: the thesis's coefficients) and reports flights/s after compilation (best
of ``--repeats`` passes over the chunks, models interleaved so that machine noise hits all alike),
compile times, the mean apogee and the ratio interpolated / simplified. With ``--max-ratio R``
exits 1 if that ratio exceeds R (the thesis saw 30x; the goal is 1.5x).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time

import jax
import numpy as np

from rocketmc.bench import seconds_per_flight
from rocketmc.campaign import load_campaign, with_overrides
from rocketmc.campaign.runner import batch_size, compile_chunk

MODELS = ("interpolated", "simplified", "linear")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--campaign", default="campaigns/lynx_nominal.toml")
    parser.add_argument("--n", type=int, default=1000)
    parser.add_argument("--repeats", type=int, default=2)
    parser.add_argument("--json", help="also write the results to this file")
    parser.add_argument("--max-ratio", type=float, help="fail if interpolated / simplified exceeds this")
    args = parser.parse_args()

    base = load_campaign(args.campaign)
    batch = batch_size(args.n)
    compiled, compile_s = {}, {}
    for model in MODELS:
        campaign = with_overrides(base, n_realizations=args.n, aero_model=model)
        t0 = time.perf_counter()
        compiled[model] = compile_chunk(campaign, batch)
        compile_s[model] = time.perf_counter() - t0
    key = jax.random.key(base.config.seed)
    best = seconds_per_flight({model: (f, batch) for model, f in compiled.items()}, key, args.repeats)
    indices = np.arange(batch, dtype=np.uint32)
    apogee = {model: float(np.nanmean(np.asarray(f(key, indices)[0]["apogee_agl_m"]))) for model, f in compiled.items()}
    results = {
        model: {"flights_per_s": round(1 / best[model], 1), "compile_s": round(compile_s[model], 1),
                "mean_apogee_agl_m": round(apogee[model], 1)}
        for model in MODELS
    }  # fmt: skip
    ratio = best["interpolated"] / best["simplified"]
    print(f"{base.config.name}, N = {args.n}, {os.cpu_count()} CPUs, jax {jax.__version__}")
    for model, r in results.items():
        print(f"  {model:<13} {r['flights_per_s']:8.1f} flights/s   compile {r['compile_s']:5.1f} s   "
              f"mean apogee {r['mean_apogee_agl_m']:.1f} m")  # fmt: skip
    print(f"  cost ratio interpolated / simplified: {ratio:.2f}x (thesis: 30x; goal <= 1.5x)")
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"campaign": base.config.name, "n": args.n, "results": results, "ratio": ratio}, f, indent=2)
    if args.max_ratio is not None and ratio > args.max_ratio:
        print(f"FAIL: ratio {ratio:.2f} > {args.max_ratio}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())

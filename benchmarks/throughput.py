"""Flights per second of a campaign after compilation, and the compile time, on this machine.

    python benchmarks/throughput.py [--campaign campaigns/lynx_nominal.toml] [--n 1000 10000]
                                    [--chunk-size 2000] [--json FILE]

Every flight goes to the ground (parachutes included for lynx_nominal). Compile time is that of
one chunk function (the runner compiles once per run); throughput is flights / wall time of the
chunks, excluding compilation.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import time

import jax
import numpy as np

from rocketmc.campaign import load_campaign, run_chunks


def measure(campaign_path: str, n: int, chunk_size: int) -> dict:
    campaign = load_campaign(campaign_path).with_overrides(n_realizations=n)
    chunk_size = min(chunk_size, n)
    t0 = time.perf_counter()
    runs = run_chunks(campaign, chunk_size)
    compile_s = next(runs)
    chunks = list(runs)
    wall = time.perf_counter() - t0 - compile_s
    flights = sum(len(c.outputs["status"]) for c in chunks)
    ok = sum(int((c.outputs["status"] == 0).sum()) for c in chunks)
    return {
        "campaign": campaign.config.name,
        "n": n,
        "chunk_size": chunk_size,
        "compile_s": round(compile_s, 2),
        "run_s": round(wall, 2),
        "flights_per_s": round(flights / wall, 1),
        "ok": ok,
        "mean_flight_time_s": float(np.nanmean(np.concatenate([c.outputs["impact_time_s"] for c in chunks]))),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--campaign", default="campaigns/lynx_nominal.toml")
    parser.add_argument("--n", type=int, nargs="+", default=[1000, 10000])
    parser.add_argument("--chunk-size", type=int, default=2000)
    parser.add_argument("--json", help="also write the results to this file")
    args = parser.parse_args()
    machine = {"cpus": os.cpu_count(), "devices": jax.local_device_count(), "jax": jax.__version__,
               "python": platform.python_version(), "x64": bool(jax.config.jax_enable_x64)}  # fmt: skip
    print(f"machine: {machine}")
    results = []
    for n in args.n:
        r = measure(args.campaign, n, args.chunk_size)
        results.append(r)
        print(f"{r['campaign']:>16}  N={r['n']:>6}  chunk={r['chunk_size']:>5}  compile {r['compile_s']:6.1f} s  "
              f"run {r['run_s']:6.1f} s  {r['flights_per_s']:7.1f} flights/s  ({r['ok']} ok)")  # fmt: skip
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"machine": machine, "results": results}, f, indent=2)


if __name__ == "__main__":
    main()

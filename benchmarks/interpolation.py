"""rocketmc's multilinear lookup against ``jax.scipy.interpolate.RegularGridInterpolator``.

    python benchmarks/interpolation.py [--n 10000 100000] [--repeats 20] [--flights 400]

1. Isolated lookups: ``jit(vmap(interpolate))`` on the Lynx DATCOM table (all 26 coefficients)
   against the reference on the same random in-range points (best of ``--repeats``).
2. The campaign's access pattern: ``lynx_nominal`` with the interpolated model (4-D body table +
   canard panel tables, looked up at every RK4 stage inside the flight loop), flown once with
   rocketmc's lookup and once with the reference swapped in; flights/s after compilation.
"""

from __future__ import annotations

import argparse
import time

import jax
import jax.numpy as jnp
import numpy as np
from jax.scipy.interpolate import RegularGridInterpolator

import rocketmc.aero.model
from rocketmc.aero.datcom import LYNX_DATCOM, load_datcom_mat
from rocketmc.campaign import load_campaign, with_overrides
from rocketmc.campaign.runner import compile_chunk
from rocketmc.math.table import interpolate


def best_time(fn, args, repeats: int) -> float:
    """Best wall time [s] of ``fn(*args)`` over ``repeats`` calls, after one compiling call."""
    jax.block_until_ready(fn(*args))
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        jax.block_until_ready(fn(*args))
        times.append(time.perf_counter() - t0)
    return min(times)


def reference_lookup(table, point):
    """``interpolate``'s contract (clamped, with the out-of-range flag) on jax.scipy's interpolator."""
    rgi = RegularGridInterpolator(table.axes, table.values, method="linear", bounds_error=False, fill_value=None)
    clamped = jnp.stack([jnp.clip(x, a[0], a[-1]) for a, x in zip(table.axes, point)])
    outside = jnp.any(jnp.stack([(x < a[0]) | (x > a[-1]) for a, x in zip(table.axes, point)]))
    return rgi(clamped[None])[0], outside


def campaign_flights_per_s(n: int, repeats: int) -> float:
    campaign = with_overrides(load_campaign("campaigns/lynx_nominal.toml"), n_realizations=n, aero_model="interpolated")
    compiled = compile_chunk(campaign, n)
    key, indices = jax.random.key(0), np.arange(n, dtype=np.uint32)
    return n / best_time(compiled, (key, indices), repeats)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--n", type=int, nargs="+", default=[10_000, 100_000])
    parser.add_argument("--repeats", type=int, default=20)
    parser.add_argument("--flights", type=int, default=400, help="realizations of the campaign measurement")
    args = parser.parse_args()

    table = load_datcom_mat(LYNX_DATCOM)
    ours = jax.jit(jax.vmap(interpolate, in_axes=(None, 0)))
    reference = RegularGridInterpolator(table.axes, table.values, method="linear", bounds_error=False, fill_value=None)
    theirs = jax.jit(lambda points: reference(points))

    rng = np.random.default_rng(0)
    print(f"Lynx DATCOM table {table.values.shape[:-1]} x {table.values.shape[-1]} outputs, {jax.devices()[0].platform}")
    for n in args.n:
        points = jnp.asarray(np.stack([rng.uniform(a[0], a[-1], n) for a in map(np.asarray, table.axes)], axis=-1))
        ours_values = ours(table, tuple(points.T))[0]
        np.testing.assert_allclose(ours_values, theirs(points), rtol=1e-12, atol=1e-12)
        t_ours = best_time(ours, (table, tuple(points.T)), args.repeats)
        t_theirs = best_time(theirs, (points,), args.repeats)
        print(
            f"N={n:>7}: rocketmc Table {n / t_ours:12.4g} points/s | "
            f"jax.scipy RegularGridInterpolator {n / t_theirs:12.4g} points/s | ratio {t_theirs / t_ours:.2f}x"
        )

    ours_rate = campaign_flights_per_s(args.flights, 2)
    rocketmc.aero.model.interpolate = reference_lookup
    theirs_rate = campaign_flights_per_s(args.flights, 2)
    print(
        f"lynx_nominal, interpolated model, N={args.flights}: rocketmc {ours_rate:.0f} flights/s | "
        f"jax.scipy RegularGridInterpolator {theirs_rate:.0f} flights/s | ratio {ours_rate / theirs_rate:.2f}x"
    )


if __name__ == "__main__":
    main()

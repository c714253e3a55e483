"""Points per second of the Lynx DATCOM lookup (all 26 coefficients), after compilation.

    python benchmarks/interpolation.py [--n 10000 100000] [--repeats 20]

Compares ``jit(vmap(interpolate))`` of rocketmc's ``Table`` with
``jax.scipy.interpolate.RegularGridInterpolator`` on the stacked values (it accepts trailing
output dimensions), both on the same random in-range points. Reports the best of ``--repeats``.
"""

from __future__ import annotations

import argparse
import time

import jax
import jax.numpy as jnp
import numpy as np
from jax.scipy.interpolate import RegularGridInterpolator

from rocketmc.aero.datcom import LYNX_DATCOM, load_datcom_mat
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


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--n", type=int, nargs="+", default=[10_000, 100_000])
    parser.add_argument("--repeats", type=int, default=20)
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


if __name__ == "__main__":
    main()

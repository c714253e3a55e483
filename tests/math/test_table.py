"""Table/interpolate against scipy's RegularGridInterpolator: inside, clamped outside, vmap, grad."""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from scipy.interpolate import RegularGridInterpolator

from rocketmc.math.table import Table, interpolate

# Both are the same multilinear formula summed in different orders (scipy: nested 1-D blends;
# ours: 2^D weighted corners), |values| <= ~300 here: they differ by a few roundings, far below 1e-12.
TOL = 1e-12


def random_table(shape, n_outputs, seed):
    """Random table with non-uniform axes (sorted uniform draws) and its scipy reference."""
    rng = np.random.default_rng(seed)
    axes = [np.sort(rng.uniform(-2.0, 3.0, n)) for n in shape]
    values = rng.normal(size=(*shape, n_outputs)) * 100.0
    names = tuple(f"x{d}" for d in range(len(shape)))
    table = Table.from_numpy(axes, values, names, tuple(f"y{k}" for k in range(n_outputs)))
    return table, RegularGridInterpolator(axes, values, method="linear"), axes, rng


def inside_points(axes, rng, n):
    return np.stack([rng.uniform(a[0], a[-1], n) for a in axes], axis=-1)


batched = jax.jit(jax.vmap(interpolate, in_axes=(None, 0)))


@pytest.mark.parametrize("shape", [(9,), (5, 7, 4), (6, 3, 8, 5)])
def test_matches_scipy_inside(shape):
    table, reference, axes, rng = random_table(shape, 3, seed=len(shape))
    points = inside_points(axes, rng, 500)
    values, out_of_range = batched(table, tuple(points.T))
    np.testing.assert_allclose(values, reference(points), rtol=TOL, atol=TOL)
    assert not np.any(out_of_range)


def test_grid_nodes_exact():
    table, reference, axes, _ = random_table((5, 7, 4), 2, seed=3)
    nodes = np.stack([g.ravel() for g in np.meshgrid(*axes, indexing="ij")], axis=-1)
    values, out_of_range = batched(table, tuple(nodes.T))
    # At a node the weight of that node is exactly 1 and the others exactly 0.
    np.testing.assert_array_equal(values, reference(nodes))
    assert not np.any(out_of_range)


def test_clamps_outside():
    table, reference, axes, rng = random_table((6, 3, 8, 5), 2, seed=4)
    lo = np.array([a[0] for a in axes])
    hi = np.array([a[-1] for a in axes])
    span = hi - lo
    points = lo + rng.uniform(-0.5, 1.5, (400, 4)) * span
    values, out_of_range = batched(table, tuple(points.T))
    # Same formula as inside, evaluated at the clipped point.
    np.testing.assert_allclose(values, reference(np.clip(points, lo, hi)), rtol=TOL, atol=TOL)
    np.testing.assert_array_equal(out_of_range, np.any((points < lo) | (points > hi), axis=1))
    assert np.all(np.isfinite(values))
    far, far_oor = interpolate(table, (1e300, -1e300, 0.0, 0.0))
    assert np.all(np.isfinite(far)) and bool(far_oor)


def test_vmap_equals_loop():
    table, _, axes, rng = random_table((6, 3, 8, 5), 4, seed=5)
    points = inside_points(axes, rng, 1000)
    points[::7] += 5.0  # some outside too
    values, out_of_range = batched(table, tuple(points.T))
    single = jax.jit(interpolate)
    for p, v, o in zip(points, np.asarray(values), np.asarray(out_of_range)):
        vl, ol = single(table, tuple(p))
        # Same operations per point; vmap may only reorder the 2^D-term sum: a few ulps.
        np.testing.assert_allclose(v, vl, rtol=TOL, atol=TOL)
        assert o == ol


def test_grad_is_cell_slope():
    table, _, axes, _ = random_table((6, 3, 8, 5), 3, seed=6)
    # Midpoint of one cell, far from its edges.
    point = tuple(0.5 * (a[1] + a[2]) if a.size > 2 else 0.5 * (a[0] + a[1]) for a in axes)
    for d in range(4):
        grad = jax.grad(lambda x: interpolate(table, point[:d] + (x,) + point[d + 1 :])[0][1])(point[d])
        h = 1e-3 * (axes[d][1] - axes[d][0])
        up = interpolate(table, point[:d] + (point[d] + h,) + point[d + 1 :])[0][1]
        down = interpolate(table, point[:d] + (point[d] - h,) + point[d + 1 :])[0][1]
        # Linear along each axis within a cell: the central difference is exact up to the rounding
        # of values ~1e2 divided by 2h ~ 1e-3 (~1e-11), so 1e-8 relative is generous.
        np.testing.assert_allclose(grad, (up - down) / (2 * h), rtol=1e-8)


def test_grad_zero_outside():
    table, _, axes, _ = random_table((5, 4), 1, seed=7)
    grad = jax.grad(lambda x: interpolate(table, (x, axes[1][1]))[0][0])(axes[0][-1] + 1.0)
    assert grad == 0.0


def test_jit_pytree_roundtrip():
    table, _, _, _ = random_table((5, 4), 2, seed=8)
    leaves, treedef = jax.tree_util.tree_flatten(table)
    assert len(leaves) == 3  # two axes + values; names are static
    rebuilt = jax.tree_util.tree_unflatten(treedef, leaves)
    assert rebuilt.axis_names == ("x0", "x1") and rebuilt.output_names == ("y0", "y1")
    values, _ = jax.jit(interpolate)(table, (jnp.float64(0.1), jnp.float64(0.2)))
    assert values.shape == (2,)


@pytest.mark.parametrize(
    ("axes", "values_shape", "match"),
    [
        ([np.array([0.0, 1.0]), np.array([0.0, 2.0, 1.0])], (2, 3, 1), "'b'"),
        ([np.array([0.0, 1.0]), np.array([0.0, 1.0, 1.0])], (2, 3, 1), "'b'"),
        ([np.array([1.0, 0.0]), np.array([0.0, 1.0, 2.0])], (2, 3, 1), "'a'"),
        ([np.array([0.0]), np.array([0.0, 1.0, 2.0])], (1, 3, 1), "'a'"),
        ([np.array([0.0, np.nan]), np.array([0.0, 1.0, 2.0])], (2, 3, 1), "'a'"),
        ([np.array([0.0, 1.0]), np.array([0.0, 1.0, 2.0])], (3, 2, 1), "shape"),
        ([np.array([0.0, 1.0]), np.array([0.0, 1.0, 2.0])], (2, 3, 2), "outputs"),
    ],
)
def test_bad_tables_raise(axes, values_shape, match):
    with pytest.raises(ValueError, match=match):
        Table.from_numpy(axes, np.zeros(values_shape), ("a", "b"), ("y",))

"""N-D multilinear interpolation of vector-valued tables, written for cheap evaluation under ``vmap``.

A ``Table`` holds D strictly increasing (not necessarily uniform) axes and values of shape
``(*grid, n_outputs)``; ``interpolate`` returns all outputs at one point from the 2^D corners of
the point's cell.
"""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np

from ..pytree import pytree_dataclass, static_field


def check_grid(axes, values, axis_names, output_names) -> None:
    """``ValueError`` naming the offending axis or size unless ``values`` (grid + (n_outputs,)) sits
    on ``axes`` (1-D, finite, strictly increasing, >= 2 points each)."""
    if len(axis_names) != len(axes):
        raise ValueError(f"{len(axes)} axes but {len(axis_names)} axis names {tuple(axis_names)}")
    for name, a in zip(axis_names, axes):
        a = np.asarray(a)
        if a.ndim != 1 or a.size < 2:
            raise ValueError(f"axis {name!r} must be 1-D with at least 2 points, got shape {a.shape}")
        if not np.all(np.isfinite(a)) or not np.all(np.diff(a) > 0):
            raise ValueError(f"axis {name!r} must be finite and strictly increasing")
    grid = tuple(np.asarray(a).size for a in axes)
    if values.shape[:-1] != grid or values.ndim != len(axes) + 1:
        raise ValueError(f"values shape {values.shape} must be grid {grid} + (n_outputs,) for axes {tuple(axis_names)}")
    if values.shape[-1] != len(output_names):
        raise ValueError(f"{values.shape[-1]} outputs but {len(output_names)} output names")


@pytree_dataclass
class Table:
    """Gridded vector-valued function: ``values[i_0, ..., i_{D-1}, k]`` at ``(axes[0][i_0], ...)``.

    Units are those of each axis and output; the names (static) document them.
    """

    axes: tuple[jnp.ndarray, ...]  # D arrays (n_d,), each strictly increasing, n_d >= 2
    values: jnp.ndarray  # (n_0, ..., n_{D-1}, n_outputs)
    axis_names: tuple[str, ...] = static_field()
    output_names: tuple[str, ...] = static_field()

    @classmethod
    def from_numpy(cls, axes, values, axis_names, output_names) -> Table:
        """Validated ``Table`` from host arrays; ``ValueError`` naming the offending axis or size."""
        axis_names = tuple(axis_names)
        output_names = tuple(output_names)
        axes = [np.asarray(a, dtype=np.float64) for a in axes]
        values = np.asarray(values, dtype=np.float64)
        check_grid(axes, values, axis_names, output_names)
        return cls(tuple(jnp.asarray(a) for a in axes), jnp.asarray(values), axis_names, output_names)


def interpolate(table: Table, point):
    """Multilinear ``values`` (n_outputs,) at ``point`` (one scalar per axis) and an out-of-range flag.

    Each coordinate is clamped to its axis range (constant extrapolation, zero gradient outside);
    ``out_of_range`` is True if any coordinate was outside. Differentiable w.r.t. ``point``.

    The point's cell (its 2^D corners, all outputs) is fetched with one ``dynamic_slice`` and
    reduced one axis at a time. One fetch matters inside the flight loop: batches there are a
    few hundred flights per core, so XLA's per-operation overhead dominates, and the earlier
    one-gather-per-corner form made a 4-D table cost 4x the flight (measured, jax 0.10 CPU).
    """
    starts, fractions = [], []
    out_of_range = jnp.asarray(False)
    for a, x in zip(table.axes, point):
        x = jnp.asarray(x, dtype=a.dtype)
        out_of_range = out_of_range | (x < a[0]) | (x > a[-1])
        xc = jnp.clip(x, a[0], a[-1])
        i = jnp.clip(jnp.searchsorted(a, xc, side="right", method="compare_all") - 1, 0, a.shape[0] - 2)
        starts.append(i)
        fractions.append((xc - a[i]) / (a[i + 1] - a[i]))  # position inside the cell, in [0, 1]
    n_outputs = table.values.shape[-1]
    cell = jax.lax.dynamic_slice(table.values, (*starts, jnp.zeros_like(starts[0])), (2,) * len(starts) + (n_outputs,))
    for t in fractions:
        cell = (1.0 - t) * cell[0] + t * cell[1]  # exact at both nodes
    return cell, out_of_range

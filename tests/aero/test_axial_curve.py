"""A Cd-vs-Mach curve finer than the build-up's Mach grid (0.05 apart) flies as given: its points are inserted in the
table's Mach axis, the rest of the table's interpolant unchanged."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.interpolate import RegularGridInterpolator

from rocketmc.aero.geometry import LYNX_CANARDS
from rocketmc.aero.sources import build_up_tables, with_axial_curve
from rocketmc.aero.tables import BODY_COEFFS

REFERENCE_POINT_M = 1.33

# A transonic drag peak at Mach 0.92, between the grid's 0.90 and 0.95, sampled every 0.01 Mach from 0.80 to 1.00
# (a wind-tunnel or CFD curve), coarser elsewhere.
MACH = np.concatenate([[0.0, 0.3, 0.6], np.round(np.arange(0.80, 1.001, 0.01), 2), [1.2]])
CD = 0.40 + 0.25 * np.exp(-(((MACH - 0.92) / 0.02) ** 2))


def zero_angle_ca(tables, mach):
    """The table's axial force at α = β = 0, at the lowest altitude, interpolated at ``mach`` (linear in Mach)."""
    body = tables.body
    at = {name: np.flatnonzero(axis == 0.0)[0] if name in ("alpha", "beta") else 0
          for name, axis in zip(body.axis_names, body.axes) if name != "mach"}  # fmt: skip
    index = tuple(slice(None) if name == "mach" else at[name] for name in body.axis_names)
    return np.interp(mach, body.axes[body.axis_names.index("mach")], body.output("CA")[index])


def test_a_curve_finer_than_the_grid_is_kept():
    base = build_up_tables(LYNX_CANARDS, REFERENCE_POINT_M)
    tables = with_axial_curve(base, MACH, CD)
    inside = MACH >= 0.05  # the build-up's grid starts at Mach 0.05 (clamped below)
    np.testing.assert_allclose(zero_angle_ca(tables, MACH[inside]), CD[inside], rtol=0, atol=1e-15)
    # what the grid alone kept of this curve (before its points were inserted): the peak of 0.650 at Mach 0.92 cut
    # to 0.466 (−28 %)
    grid = base.body.axes[base.body.axis_names.index("mach")]
    resampled = np.interp(MACH[inside], grid, np.interp(grid, MACH, CD))
    assert resampled[MACH[inside] == 0.92] == pytest.approx(0.4657, abs=1e-4)
    # every other output's multilinear interpolant is the table's own
    points = np.random.default_rng(0).uniform([a[0] for a in base.body.axes], [a[-1] for a in base.body.axes],
                                              (500, len(base.body.axes)))  # fmt: skip
    for name in BODY_COEFFS[1:]:
        k = BODY_COEFFS.index(name)
        before = RegularGridInterpolator(base.body.axes, base.body.values[..., k])(points)
        after = RegularGridInterpolator(tables.body.axes, tables.body.values[..., k])(points)
        np.testing.assert_allclose(after, before, rtol=1e-12, atol=1e-12)


def test_a_curve_on_the_grid_leaves_the_axis_as_it_was():
    base = build_up_tables(LYNX_CANARDS, REFERENCE_POINT_M)
    lynx = with_axial_curve(base, [0.0, 0.2, 0.5, 0.7, 0.85, 1.0], [0.420, 0.420, 0.378, 0.362, 0.383, 0.605])
    for before, after in zip(base.body.axes, lynx.body.axes):
        assert np.array_equal(before, after)
    assert lynx.body.values.shape == base.body.values.shape

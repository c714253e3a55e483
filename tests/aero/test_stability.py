"""The static margin against its closed form on a linear model, and the interpolated tables' slopes
against ``simplify``'s (the same central difference on the whole grid)."""

from __future__ import annotations

import math

import pytest

from rocketmc.aero.geometry import LYNX_CANARDS
from rocketmc.aero.model import TableAero, from_virtual_commands, linear_derivatives, simplify
from rocketmc.aero.sources import build_up_tables
from rocketmc.aero.stability import centre_of_pressure_x_m, normal_force_slopes, static_margin_calibers


def linear(cn_alpha, cm_alpha, moment_ref_x_m=0.2, d=0.15):
    return from_virtual_commands(0.0177, d, moment_ref_x_m, [0.0, 1.0], [0.4, 0.5], [0.0] * 4, cn_alpha, 0.0,
                                 cm_alpha, 0.0, 0.0, 0.0, 0.0, 0.0, -100.0, -10.0)  # fmt: skip


@pytest.mark.parametrize("cn_alpha, cm_alpha, cg_x_m, margin", [
    (10.0, -15.0, 0.0, (0.0 - (0.2 - 1.5 * 0.15)) / 0.15),  # cp 1.5 d aft of the moment reference: stable
    (10.0, 5.0, 0.2, -0.5),  # cp 0.5 d ahead of the CG at the moment reference: unstable
    (10.0, 0.0, 0.2, 0.0),  # cp at the CG: neutral
])  # fmt: skip
def test_margin_is_the_cg_ahead_of_the_cp_in_calibers(cn_alpha, cm_alpha, cg_x_m, margin):
    aero = linear(cn_alpha, cm_alpha)
    assert centre_of_pressure_x_m(aero, 0.3) == pytest.approx(0.2 + 0.15 * cm_alpha / cn_alpha, abs=1e-12)
    assert static_margin_calibers(aero, cg_x_m, 0.3) == pytest.approx(margin, abs=1e-12)


def test_no_restoring_normal_force_has_no_margin():
    assert math.isnan(static_margin_calibers(linear(0.0, -1.0), 0.0, 0.3))


@pytest.mark.parametrize("mach", [0.1, 0.3, 0.62])
def test_table_slopes_are_simplify_s(mach):
    """One point's central difference equals ``simplify``'s on the grid at a Mach node and, between nodes,
    its interpolation in Mach (inside a cell the table is multilinear, so the α slope is linear in Mach);
    1e-9 relative: the rounding of the two differences."""
    aero = TableAero.from_tables(build_up_tables(LYNX_CANARDS, 1.33), 1.33)
    c = linear_derivatives(simplify(aero), mach, 0.0)
    cn_alpha, cm_alpha = normal_force_slopes(aero, mach, 0.0)
    assert cn_alpha == pytest.approx(c["CNa"], rel=1e-9) and cm_alpha == pytest.approx(c["Cma"], rel=1e-9)

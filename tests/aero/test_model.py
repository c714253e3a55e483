"""The interpolated and simplified aerodynamic models: conventions, consistency, the shared wrench."""

from __future__ import annotations

import dataclasses

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from rocketmc.aero import AirData
from rocketmc.aero.canards import allocate
from rocketmc.aero.geometry import LYNX_CANARDS
from rocketmc.aero.model import (
    TableAero,
    aero_coefficients,
    aero_wrench,
    from_virtual_commands,
    linear_derivatives,
    simplify,
    table_coefficients,
)
from rocketmc.aero.sources import build_up_tables, with_axial_curve
from rocketmc.math import Vec3
from rocketmc.math.table import Table

from ..conftest import CAMPAIGNS

REFERENCE_POINT_M = 1.33
THESIS = dict(
    reference_area_m2=0.01767, reference_length_m=0.15, moment_ref_x_m=0.0,
    ca0_mach=[0.0, 0.2, 0.5, 0.7, 0.85, 1.0], ca0=[0.420, 0.420, 0.378, 0.362, 0.383, 0.605],
    ca_u=[0.4001, 0.4001, 0.5739, 0.8899], cn_alpha=24.0744, cn_delta=3.4045, cm_alpha=-37.2959,
    cm_delta=21.8445, cl0=-0.03, cl_delta=2.3963, cn_q=308.0, cy_r=308.0, cm_q=-1813.0, cl_p=-19.0,
)  # fmt: skip
ZERO_RATES = Vec3(0.0, 0.0, 0.0)


def air(alpha=0.0, beta=0.0, mach=0.3, altitude=1500.0, airspeed=100.0):
    return AirData(airspeed, alpha, beta, mach, 0.5 * 1.0 * airspeed**2, 1.0, altitude)


@pytest.fixture(scope="module")
def interpolated():
    tables = with_axial_curve(build_up_tables(LYNX_CANARDS, REFERENCE_POINT_M), THESIS["ca0_mach"], THESIS["ca0"])
    return TableAero.from_tables(tables, REFERENCE_POINT_M)


@pytest.fixture(scope="module")
def simplified(interpolated):
    return simplify(interpolated)


def coefficients(aero, air_data, deflections=(0.0, 0.0, 0.0, 0.0), omega_b=ZERO_RATES, cg_x=0.0):
    return aero_coefficients(aero, air_data, omega_b, cg_x, jnp.asarray(deflections))[0]


def test_thesis_linear_model_in_fin_deflections():
    """The thesis's formulas per virtual command, evaluated through the fin-deflection form."""
    lin = from_virtual_commands(**THESIS)
    a = air(alpha=0.01, beta=-0.02, mach=0.3)
    u_yaw, u_pitch, u_roll = 0.02, 0.05, -0.03
    c = coefficients(lin, a, allocate(u_yaw, u_pitch, u_roll))
    ca0 = np.interp(0.3, THESIS["ca0_mach"], THESIS["ca0"])
    ca_u = THESIS["ca_u"]
    # float64 arithmetic only: the two forms differ by rounding
    np.testing.assert_allclose(c.ca, ca0 + ca_u[0] * u_yaw**2 + ca_u[1] * u_pitch**2 + ca_u[2] * u_roll**2, rtol=1e-12)
    np.testing.assert_allclose(c.cn, 24.0744 * 0.01 + 3.4045 * u_pitch, rtol=1e-12)
    np.testing.assert_allclose(c.cy, -24.0744 * -0.02 + 3.4045 * u_yaw, rtol=1e-12)
    np.testing.assert_allclose(c.cm, -37.2959 * 0.01 + 21.8445 * u_pitch, rtol=1e-12)
    np.testing.assert_allclose(c.cn_yaw, 37.2959 * -0.02 + 21.8445 * u_yaw, rtol=1e-12)
    np.testing.assert_allclose(c.cl, -0.03 + 2.3963 * u_roll, rtol=1e-12)


@pytest.mark.parametrize("panel", [0, 1, 2, 3])
def test_canard_sign_conventions(interpolated, panel):
    """Panel i at roll φ_i = i·90° (1 up, 2 starboard, 3 down, 4 port) pushed along (0, −cos φ, −sin φ)
    by a positive deflection, which also rolls the rocket negatively (the thesis's mixing)."""
    delta = np.zeros(4)
    delta[panel] = np.deg2rad(3.0)
    c = coefficients(interpolated, air(), delta)
    c0 = coefficients(interpolated, air())
    push_y, push_z = -np.cos(panel * np.pi / 2), -np.sin(panel * np.pi / 2)
    force_y, force_up = float(c.cy - c0.cy), float(c.cn - c0.cn)
    assert np.sign(np.round(force_y, 9)) == np.sign(np.round(push_y, 9))
    assert np.sign(np.round(force_up, 9)) == np.sign(np.round(-push_z, 9))
    # The canards are ahead of the moment point: an upward force pitches up, a rightward one yaws right.
    assert np.sign(np.round(float(c.cm - c0.cm), 9)) == np.sign(np.round(force_up, 9))
    assert np.sign(np.round(float(c.cn_yaw - c0.cn_yaw), 9)) == np.sign(np.round(force_y, 9))
    assert c.cl < c0.cl


@pytest.mark.parametrize(
    ("alpha_deg", "beta_deg", "command_deg", "atol"),
    [
        # One input at a time, inside the tables' first cells (±1°) where both are linear: equal to
        # rounding (the central differences see two cells of equal slope).
        (0.5, 0.0, (0.0, 0.0, 0.0), 1e-12),
        (0.0, -0.4, (0.0, 0.0, 0.0), 1e-12),
        (0.0, 0.0, (0.3, 0.5, 0.2), 1e-12),
        # All together: the panels' crossflow lift ∝ (i+δ)|i+δ| adds a term 2·i·δ that the linear
        # model lacks, ~2e-4 in a panel's CN, ~2e-3 in Cm through the canards' 6-calibre arm.
        (0.5, -0.4, (0.3, 0.5, 0.2), 3e-3),
    ],
)
def test_simplified_agrees_with_interpolated_at_small_angles(interpolated, simplified, alpha_deg, beta_deg,
                                                             command_deg, atol):  # fmt: skip
    """Linearised from the interpolated model itself, the two agree to first order at small angles."""
    for mach in (0.2, 0.45, 0.8):
        a = air(alpha=np.deg2rad(alpha_deg), beta=np.deg2rad(beta_deg), mach=mach)
        delta = jnp.asarray(allocate(*np.deg2rad(command_deg)))
        ci = coefficients(interpolated, a, delta, cg_x=interpolated.moment_ref_x_m)
        cs = coefficients(simplified, a, delta)
        for name in ("cy", "cn", "cm", "cn_yaw", "cl"):
            np.testing.assert_allclose(getattr(cs, name), getattr(ci, name), rtol=0, atol=atol, err_msg=name)
        # CA: the simplified model keeps CA(Mach) + δᵀQδ; the tables add OpenRocket's angle factor
        # (+0.3 % at 1° in α and in β) and the canards' induced drag CN(i)·sin δ, whose
        # incidence-deflection product is second order too: < 1 % here
        np.testing.assert_allclose(cs.ca, ci.ca, rtol=1e-2)


def test_canard_rates_damp_through_the_panel_incidence(interpolated, simplified):
    """A pitch rate q changes the horizontal canards' incidence by −q·x/V: their share of Cmq (per
    ω·d/(2V)) is −2·CNα_c·(x/d)², CNα_c being their share of the normal-force slope and x their arm."""
    no_canards = dataclasses.replace(interpolated, canard_table=None, canard_roll_rad=jnp.zeros(0))
    body = table_coefficients(no_canards, air(), ZERO_RATES, interpolated.moment_ref_x_m, jnp.zeros(0))[0]
    d = linear_derivatives(simplified, 0.3, 1500.0)
    body_slope = linear_derivatives(simplify(no_canards), 0.3, 1500.0)["CNa"]
    arm = float((interpolated.canard_cp_x_m - interpolated.moment_ref_x_m) / interpolated.reference_length_m)
    expected = -2 * (d["CNa"] - body_slope) * arm**2
    # central differences of a table: measured 5.5e-7, 1e-5 is 18x that
    assert d["Cmq"] - float(body.cm_q) == pytest.approx(expected, rel=1e-5)


def test_wrench_under_canopy_keeps_only_damping(simplified):
    a = air(alpha=0.1)
    omega = Vec3(1.0, 0.5, -0.3)
    c = coefficients(simplified, a, omega_b=omega)
    force, moment = aero_wrench(simplified, c, a, omega, -5.0, True)
    assert (float(force.x), float(force.y), float(force.z)) == (0.0, 0.0, 0.0)
    qsd = a.qbar * simplified.reference_area_m2 * simplified.reference_length_m
    rate = 0.5 * simplified.reference_length_m / a.airspeed
    np.testing.assert_allclose(moment.x, qsd * -5.0 * omega.x * rate, rtol=1e-12)
    np.testing.assert_allclose(moment.y, qsd * c.cm_q * omega.y * rate, rtol=1e-12)


def test_moment_about_the_cg_does_not_depend_on_the_moment_reference(interpolated):
    """Re-referencing the tables and moving moment_ref_x_m with them leaves the moment about the CG
    unchanged (the canards carry their own point of action)."""
    tables = with_axial_curve(build_up_tables(LYNX_CANARDS, REFERENCE_POINT_M), THESIS["ca0_mach"], THESIS["ca0"])
    moved = TableAero.from_tables(tables.re_referenced(1.6), REFERENCE_POINT_M)
    cg_x = -0.12
    a = air(alpha=0.05, beta=0.03)
    delta = jnp.asarray(np.deg2rad([1.0, -2.0, 0.5, 3.0]))

    def moment_about_cg(aero):
        c = coefficients(aero, a, delta, cg_x=cg_x)
        force, moment = aero_wrench(aero, c, a, ZERO_RATES, 0.0, False)
        arm = Vec3(aero.moment_ref_x_m - cg_x, 0.0, 0.0)
        return np.array(moment + arm.cross(force))

    np.testing.assert_allclose(moment_about_cg(moved), moment_about_cg(interpolated), rtol=1e-9, atol=1e-9)


def test_models_are_jittable_vmappable_and_differentiable(interpolated, simplified):
    alphas = jnp.linspace(-0.2, 0.2, 5)
    for aero in (interpolated, simplified):
        cn = jax.jit(jax.vmap(lambda al: coefficients(aero, air(alpha=al)).cn))(alphas)
        assert np.all(np.diff(np.asarray(cn)) > 0)
        slope = jax.grad(lambda al: coefficients(aero, air(alpha=al)).cn)(0.01)
        assert np.isfinite(slope) and slope > 0


def test_out_of_range_flag(interpolated):
    inside = aero_coefficients(interpolated, air(alpha=0.1), ZERO_RATES, 0.0, jnp.zeros(4))[1]
    outside = aero_coefficients(interpolated, air(alpha=1.0), ZERO_RATES, 0.0, jnp.zeros(4))[1]
    assert not inside and outside


def test_interpolated_aero_is_a_pytree_with_static_panel_count(interpolated, simplified):
    """The models flatten to their arrays only, in field order (the tables' names static, an absent
    power-on table no leaf), unflatten to the same model, a name is part of the structure (changing
    it recompiles) and a value is not; the panel count is static under jit (an array shape), and
    LinearAero's is a static int; vmap over one batched field gives each lane its own value."""
    leaves, tree = jax.tree_util.tree_flatten(interpolated)
    body, panel = interpolated.body, interpolated.canard_table
    expected = [
        interpolated.reference_area_m2, interpolated.reference_length_m, interpolated.moment_ref_x_m,
        *body.axes, body.values, *panel.axes, panel.values, interpolated.canard_roll_rad,
        interpolated.canard_cp_x_m, interpolated.canard_cp_radius_m, interpolated.drag_scale, interpolated.cl0,
    ]  # fmt: skip
    assert len(leaves) == len(expected) and all(leaf is x for leaf, x in zip(leaves, expected))
    assert all(isinstance(leaf, jax.Array) for leaf in leaves)
    rebuilt = jax.tree_util.tree_unflatten(tree, leaves)
    assert type(rebuilt) is TableAero and rebuilt.power_on_ca is None and rebuilt.n_canards == 4
    for table, original in ((rebuilt.body, body), (rebuilt.canard_table, panel)):
        assert (table.axis_names, table.output_names) == (original.axis_names, original.output_names)
    renamed = dataclasses.replace(body, output_names=tuple(reversed(body.output_names)))
    assert jax.tree_util.tree_structure(dataclasses.replace(interpolated, body=renamed)) != tree
    assert jax.tree_util.tree_structure(dataclasses.replace(interpolated, cl0=jnp.asarray(0.5))) == tree
    assert jax.jit(lambda aero: jnp.zeros(aero.n_canards))(interpolated).shape == (4,)

    lin_leaves, lin_tree = jax.tree_util.tree_flatten(simplified)
    assert all(isinstance(leaf, jax.Array) for leaf in lin_leaves)  # n_canards is not a leaf
    assert type(jax.tree_util.tree_unflatten(lin_tree, lin_leaves).n_canards) is int
    assert jax.tree_util.tree_structure(dataclasses.replace(simplified, n_canards=3)) != lin_tree

    scales, offsets = jnp.array([0.8, 1.0, 1.25]), jnp.array([-0.03, 0.0, 0.02])

    def ca_cl(aero):
        c = coefficients(aero, air(alpha=0.05))
        return c.ca, c.cl

    for aero in (interpolated, simplified):  # the fixtures' drag_scale = 1, cl0 = 0
        base = jax.jit(ca_cl)(aero)
        batched = dataclasses.replace(aero, drag_scale=scales, cl0=offsets)
        in_axes = dataclasses.replace(jax.tree_util.tree_map(lambda _: None, aero), drag_scale=0, cl0=0)
        ca, cl = jax.jit(jax.vmap(ca_cl, in_axes=(in_axes,)))(batched)
        np.testing.assert_allclose(ca, scales * base[0], rtol=1e-12)
        np.testing.assert_allclose(cl, base[1] + offsets, rtol=0, atol=1e-15)


def test_power_on_axial_force(interpolated, simplified):
    """While the motor burns both models add the power-on change ΔCA(Mach), scaled by drag_scale."""
    increment = Table.from_numpy(([0.0, 1.0],), [[-0.1], [-0.2]], ("mach",), ("dCA",))
    for aero in (interpolated, simplified):
        a = dataclasses.replace(aero, power_on_ca=increment, drag_scale=jnp.asarray(1.1))
        off, _ = aero_coefficients(a, air(mach=0.3), ZERO_RATES, 0.0, jnp.zeros(4), False)
        on, _ = aero_coefficients(a, air(mach=0.3), ZERO_RATES, 0.0, jnp.zeros(4), True)
        assert float(on.ca - off.ca) == pytest.approx(1.1 * -0.13, rel=1e-12)  # linear in Mach: exact


def test_build_up_rocket_gets_the_power_on_base_drag_change():
    """A built-up rocket without a Cd curve loses base drag while burning: OpenRocket's power-on
    base area is the body's minus the motor's, so ΔCA = −base drag × (d_motor/d_body)²."""
    from rocketmc.aero import drag
    from rocketmc.campaign import load_campaign

    campaign = load_campaign(CAMPAIGNS / "custom_rocket.toml")
    increment = campaign.aero.power_on_ca
    mach = np.asarray(increment.axes[0])
    expected = -drag.base_drag_coefficient(mach) * (0.075 / 0.127) ** 2
    np.testing.assert_allclose(np.asarray(increment.values)[:, 0], expected, rtol=1e-9)

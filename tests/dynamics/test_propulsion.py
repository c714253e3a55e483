"""The solid motor: the vendored L1350 curve, impulse, propellant consumption, grain inertia,
and the thrust-curve reader's errors."""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from scipy.integrate import quad, trapezoid

from rocketmc.dynamics import Motor, propellant_mass, read_thrust_curve, thrust
from rocketmc.dynamics.propulsion import ThrustCurveError, cumulative_impulse, delivered_impulse, grain_inertia

# Lynx's grain (data/rockets/lynx.toml, from the thesis): propellant, outer/inner diameter, length.
M0, D_OUT, D_IN, LENGTH = 1.905, 0.075, 0.020, 0.532
IGNITION = 0.5  # an ignition delay, so that every time below is also checked for the offset
CERTIFIED_IMPULSE = 4263.0  # N·s, the "4263" of the designation 4263-L1350-CS-P


@pytest.fixture(scope="module")
def curve(l1350_path):
    return read_thrust_curve(l1350_path)


@pytest.fixture(scope="module")
def motor(curve):
    t, f = curve
    return Motor(
        time_s=jnp.asarray(t),
        thrust_n=jnp.asarray(f),
        impulse_ns=jnp.asarray(cumulative_impulse(t, f)),
        ignition_time_s=jnp.asarray(IGNITION),
        propellant_mass_kg=jnp.asarray(M0),
        grain_outer_diameter_m=jnp.asarray(D_OUT),
        grain_inner_diameter_m=jnp.asarray(D_IN),
        grain_length_m=jnp.asarray(LENGTH),
        grain_center_x_m=jnp.asarray(-0.884),
        nozzle_x_m=jnp.asarray(-1.15),
    )


@pytest.fixture(scope="module")
def along(motor):
    """jit(vmap) of the motor functions over simulation times (one compilation)."""
    fn = jax.jit(jax.vmap(lambda t: (thrust(motor, t), delivered_impulse(motor, t), propellant_mass(motor, t))))
    return lambda t: tuple(np.asarray(x) for x in fn(jnp.asarray(t, dtype=float)))


def test_reads_the_vendored_rasp_file(curve):
    t, f = curve
    # 15 data rows after the header line, plus the implicit ignition point (0, 0) RASP leaves out
    assert t.shape == f.shape == (16,)
    assert (t[0], f[0]) == (0.0, 0.0)
    assert (t[1], f[1]) == (0.016, 1421.724)  # first data row, verbatim
    assert (t[-1], f[-1]) == (3.284, 0.0)  # last row: burnout
    assert np.all(np.diff(t) > 0) and np.all(f >= 0)


def test_total_impulse(curve, motor, along):
    t, f = curve
    _, impulse, _ = along([IGNITION + t[-1], IGNITION + t[-1] + 10.0])
    reference = trapezoid(f, t)  # exact integral of the piecewise-linear curve
    np.testing.assert_allclose(impulse, reference, rtol=1e-13)  # same sum, different order: rounding
    # The RASP curve is a 15-point digitisation of the certification trace, so its integral is not
    # exactly the certified total: 4280.2 N·s here, +0.4 %. 1 % is the tolerance of the motor
    # classes' published impulse and catches any unit or curve-reading error.
    assert reference == pytest.approx(CERTIFIED_IMPULSE, rel=0.01)
    assert float(motor.total_impulse_ns) == pytest.approx(reference, rel=1e-13)


def test_delivered_impulse_is_the_integral_of_thrust(curve, along):
    t, f = curve
    taus = np.array([0.0, 0.008, 0.016, 0.2, 0.5, 1.0, 1.28, 2.0, 2.9, 3.1, 3.2])
    _, impulse, _ = along(IGNITION + taus)
    for tau, got in zip(taus, impulse):
        # adaptive quadrature of np.interp with the breakpoints given: exact to ~1e-10 N·s
        ref, _ = quad(lambda x: np.interp(x, t, f), 0.0, tau, points=t[(t > 0) & (t < tau)], epsabs=1e-10, limit=200)
        assert got == pytest.approx(ref, rel=1e-10, abs=1e-9), tau
    _, before, _ = along([0.0, IGNITION - 1e-9])
    np.testing.assert_array_equal(before, 0.0)  # nothing before ignition


def test_thrust_follows_the_curve_and_is_zero_outside(curve, along):
    t, f = curve
    taus = np.linspace(0.0, t[-1], 157)
    force, _, _ = along(IGNITION + taus)
    # interp1d and np.interp round differently: 1e-12 relative of ~1500 N
    np.testing.assert_allclose(force, np.interp(taus, t, f), rtol=1e-12, atol=1e-9)
    force, _, _ = along(IGNITION + t[1:])
    np.testing.assert_allclose(force, f[1:], rtol=1e-12, atol=1e-9)  # at the curve points
    outside, _, _ = along([-1.0, 0.0, IGNITION - 1e-6, IGNITION + t[-1] + 1e-6, 100.0])
    np.testing.assert_array_equal(outside, 0.0)


def test_propellant_from_initial_mass_to_zero(curve, along):
    t, _ = curve
    _, _, m = along([0.0, IGNITION, IGNITION + t[-1], IGNITION + t[-1] + 0.5, 1e3])
    assert m[0] == M0 and m[1] == M0  # before and at ignition: full (1 − 0/I = 1 exactly)
    # Compiled, m0·(1 − I/I_tot) with I == I_tot leaves a residue of a few 1e-19 kg (XLA evaluates
    # the quotient with a reciprocal and FMA; propellant_mass clamps it at 0): 1e-15 kg is 2 ulp of m0.
    np.testing.assert_allclose(m[2:], 0.0, rtol=0, atol=1e-15)


def test_propellant_exactly_zero_after_burnout_op_by_op(curve, motor):
    """Op by op, the delivered impulse at burnout is the same sum as the total (last segment
    0.5·Δt·(f_i + 0)), so the quotient is exactly 1 and the propellant exactly 0."""
    t, _ = curve
    for time in (IGNITION + t[-1], IGNITION + t[-1] + 0.5, 1e3):
        assert float(delivered_impulse(motor, time)) == float(motor.total_impulse_ns)
        assert float(propellant_mass(motor, time)) == 0.0


def test_compiled_propellant_never_negative(curve, along):
    t, _ = curve
    _, _, m = along([IGNITION + t[-1], IGNITION + t[-1] + 0.5, 1e3])
    assert np.all(m >= 0.0)


def test_propellant_is_monotone(curve, along):
    t, f = curve
    times = np.linspace(0.0, IGNITION + t[-1] + 1.0, 4001)
    force, _, m = along(times)
    dm = np.diff(m)
    assert np.all(dm <= 0.0)  # never grows
    burning = (force[1:] > 0) & (force[:-1] > 0)
    assert np.all(dm[burning] < 0.0)  # strictly decreasing while there is thrust
    assert m.min() >= -1e-15  # see test_propellant_from_initial_mass_to_zero


def test_mass_flow_proportional_to_thrust(curve, motor, along):
    """ṁ = −F·m0/I_tot, by central differences."""
    t, _ = curve
    total = float(motor.total_impulse_ns)
    # Points inside segments (not at breakpoints, where ṁ has a kink).
    taus = 0.5 * (t[1:] + t[:-1])[1:]
    dt = 1e-5
    _, _, m_plus = along(IGNITION + taus + dt)
    _, _, m_minus = along(IGNITION + taus - dt)
    force, _, _ = along(IGNITION + taus)
    flow = (m_plus - m_minus) / (2 * dt)
    # m(t) is quadratic inside a segment, so the central difference has no truncation error; the
    # rounding of m (~2e-16·m0) over 2·dt gives ~2e-11 kg/s, against flows of 0.03..0.7 kg/s.
    np.testing.assert_allclose(flow, -force * M0 / total, rtol=1e-8, atol=1e-9)


def _hollow_cylinder(mass, d_out, d_in, length):
    """Inertia about the centre from the density integral: I_xx = ρ ∫ r² dV, I_yy = ρ ∫ (y² + x²) dV."""
    rho = mass / (np.pi * length * (d_out**2 - d_in**2) / 4)
    r_o, r_i = d_out / 2, d_in / 2
    ixx = rho * length * np.pi * (r_o**4 - r_i**4) / 2  # 2π L ∫ r³ dr
    iyy = ixx / 2 + rho * np.pi * (r_o**2 - r_i**2) * length**3 / 12  # ½ polar + ∫ x² dm
    return ixx, iyy


def test_grain_inertia_closed_form(motor):
    ixx, iyy = grain_inertia(motor, M0)
    ref_ixx, ref_iyy = _hollow_cylinder(M0, D_OUT, D_IN, LENGTH)
    assert float(ixx) == pytest.approx(ref_ixx, rel=1e-13)  # two forms of one expression: rounding
    assert float(iyy) == pytest.approx(ref_iyy, rel=1e-13)
    # Half burnt: the core grows, outer diameter and length fixed, density unchanged.
    m = 0.5 * M0
    rho = M0 / (np.pi * LENGTH * (D_OUT**2 - D_IN**2) / 4)
    d_in = np.sqrt(D_OUT**2 - 4 * m / (rho * np.pi * LENGTH))
    ixx, iyy = grain_inertia(motor, m)
    ref_ixx, ref_iyy = _hollow_cylinder(m, D_OUT, d_in, LENGTH)
    assert float(ixx) == pytest.approx(ref_ixx, rel=1e-12)
    assert float(iyy) == pytest.approx(ref_iyy, rel=1e-12)


def test_grain_inertia_thin_shell_limit(motor):
    """Burning outward leaves a thin shell at the outer radius: I_xx → m r_o², I_yy → m (r_o²/2 + L²/12)."""
    r_o = D_OUT / 2
    for m in (1e-6 * M0, 1e-9 * M0):
        ixx, iyy = grain_inertia(motor, m)
        # the shell's own thickness enters at relative order m/m0
        assert float(ixx) / m == pytest.approx(r_o**2, rel=10 * m / M0)
        assert float(iyy) / m == pytest.approx(r_o**2 / 2 + LENGTH**2 / 12, rel=10 * m / M0)
    ixx, iyy = grain_inertia(motor, 0.0)
    assert (float(ixx), float(iyy)) == (0.0, 0.0)  # burnt out: no NaN


def test_scaled_thrust_still_burns_its_propellant(lynx_campaign):
    """thrust_scale (a dispersed parameter) scales F and I_tot together: same mass, same burn time."""
    from rocketmc.campaign.model import flight_params

    key = jax.random.key(0)
    m = flight_params(lynx_campaign, {**lynx_campaign.nominal, "rocket.motor.thrust_scale": 1.1}, key).rocket.motor
    nominal = flight_params(lynx_campaign, lynx_campaign.nominal, key).rocket.motor
    assert float(m.total_impulse_ns) == pytest.approx(1.1 * float(nominal.total_impulse_ns), rel=1e-15)
    t_bo = float(m.ignition_time_s + m.burn_time_s)
    assert float(propellant_mass(m, t_bo)) == 0.0
    for t in (0.6, 1.5, 3.0):  # the same fraction burnt at every time
        assert float(propellant_mass(m, t)) == pytest.approx(float(propellant_mass(nominal, t)), rel=1e-14)


# --------------------------------------------------------------------------- reading errors

GOOD_HEADER = "; a comment\nL1 75 486 P 2.0 3.5 CTI\n"


@pytest.mark.parametrize(
    ("name", "text", "match"),
    [
        ("empty.eng", "", "fewer than two"),
        ("comments.eng", "; only a comment\n", "fewer than two"),
        ("header_only.eng", GOOD_HEADER, "fewer than two"),
        ("one_point.eng", GOOD_HEADER + "0.1 100\n", "fewer than two"),
        ("word.eng", GOOD_HEADER + "0.1 100\n0.2 abc\n", "cannot read"),
        ("short_row.eng", GOOD_HEADER + "0.1 100\n0.2\n", "cannot read"),
        ("decreasing.eng", GOOD_HEADER + "0.2 5\n0.1 3\n", "increase"),
        ("repeated.eng", GOOD_HEADER + "0.1 5\n0.1 3\n", "increase"),
        ("negative.eng", GOOD_HEADER + "0.1 5\n0.2 -3\n", ">= 0"),
        ("negative_time.csv", "-0.1,5\n0.2,3\n", ">= 0"),
        ("late_header.csv", "0.0,0\n0.1,5\ntime,thrust\n0.2,3\n", "cannot read"),
    ],
)
def test_bad_thrust_files_raise(tmp_path, name, text, match):
    path = tmp_path / name
    path.write_text(text)
    with pytest.raises(ThrustCurveError, match=match):
        read_thrust_curve(path)


def test_missing_file_raises(tmp_path):
    with pytest.raises(ThrustCurveError, match="not found"):
        read_thrust_curve(tmp_path / "missing.eng")
    assert issubclass(ThrustCurveError, ValueError)


def test_csv_with_header_and_explicit_origin(tmp_path):
    path = tmp_path / "curve.csv"
    path.write_text("time_s, thrust_n\n0.0, 0.0\n0.5, 100.0\n1.0, 0.0\n")
    t, f = read_thrust_curve(path)
    np.testing.assert_array_equal(t, [0.0, 0.5, 1.0])  # (0, 0) present: not added twice
    np.testing.assert_array_equal(f, [0.0, 100.0, 0.0])
    np.testing.assert_allclose(cumulative_impulse(t, f), [0.0, 25.0, 50.0], rtol=1e-15)


def test_rocksim_rse_reads_the_same_curve_as_the_eng(tmp_path, curve):
    """The L1350 curve written as RockSim XML (the format ThrustCurve.org serves) reads back the same."""
    t, f = curve
    points = "".join(f'<eng-data t="{float(ti)!r}" f="{float(fi)!r}" m="0" cg="0"/>' for ti, fi in zip(t[1:], f[1:]))
    path = tmp_path / "L1350.rse"
    path.write_text(f'<engine-database><engine-list><engine code="L1350"><data>{points}</data></engine>'
                    "</engine-list></engine-database>")  # fmt: skip
    t_rse, f_rse = read_thrust_curve(path)
    np.testing.assert_array_equal(t_rse, t)  # repr round-trips floats exactly
    np.testing.assert_array_equal(f_rse, f)
    bad = tmp_path / "bad.rse"
    bad.write_text("<engine-database><engine><data><eng-data t='0.1'/></data></engine></engine-database>")
    with pytest.raises(ThrustCurveError, match="lacks a numeric t or f"):
        read_thrust_curve(bad)
    bad.write_text("not xml <")
    with pytest.raises(ThrustCurveError, match="RockSim"):
        read_thrust_curve(bad)


@pytest.mark.parametrize("row", ["0.2 nan", "nan 3", "0.2 inf"])
def test_non_finite_values_raise(tmp_path, row):
    path = tmp_path / "nan.eng"
    path.write_text(GOOD_HEADER + "0.1 5\n" + row + "\n0.3 0\n")
    with pytest.raises(ThrustCurveError):
        read_thrust_curve(path)

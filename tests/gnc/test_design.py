"""LQI gain design (docs/gnc.md §5): the plant against docs/lynx.md's dimensional forces, ZOH against scipy.signal,
the DARE against a Riccati iteration, docs/gnc.md's reference gains for the thesis plant, and the gain schedule.

The thesis plant: m 22 kg, Ixx 0.06, Iyy 6.437 kg·m², S = π·0.15²/4, d 0.15 m, docs/lynx.md's linear
coefficients (force damping CY_r = CN_q = 154 per ω·d/V as the thesis writes it), dt 0.02 s, the
weights flown (Q = diag(0, 0, 0, 5, 5, 0, 0, 0, 10, 10, 10), R = 100·I3).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.linalg
import scipy.signal

from rocketmc.gnc.design import (
    THESIS_DT,
    THESIS_OMEGA_A,
    THESIS_Q,
    THESIS_R,
    PlantPoint,
    augment,
    density,
    discretise,
    flown_loop,
    gain_schedule,
    lqi_gain,
    lqi_plant,
)

LYNX = dict(
    cy_beta=-24.0744, cy_r=154.0, cy_delta=3.4045, cn_alpha=24.0744, cn_q=154.0, cn_delta=3.4045,
    cl_p=-19.0, cl_delta=2.3963, cm_alpha=-37.2959, cm_q=-1813.0, cm_delta=21.8445,
    cn_yaw_beta=37.2959, cn_r=-1813.0, cn_yaw_delta=21.8445,
    mass=22.0, ixx=0.06, iyy=6.437, area=math.pi * 0.15**2 / 4.0, diameter=0.15,
)

# Channels of K (rows yaw, pitch, roll) and the augmented states each one sees: the plant decouples
# into {v, r, u_y, e_r}, {w, q, u_p, e_q}, {p, u_r, e_p}; every other entry of K is structurally zero.
CHANNELS = ((0, 4, 5, 10), (1, 3, 6, 9), (2, 7, 8))

# docs/gnc.md §5's reference gains (4 decimals): yaw row at (v, r, u_y, e_r), roll row at (p, u_r, e_p);
# the pitch row is the yaw row with the sign of w flipped (at (w, q, u_p, e_q)).
REFERENCES = {
    ("euler", 100.0, 1.2133): ((0.0132, 0.1011, 0.5017, -0.2955), (0.0358, 1.1791, -0.2710)),
    ("euler", 200.0, 1.1336): ((0.0157, 0.0533, 1.4627, -0.2551), (0.0204, 2.0816, -0.2398)),
    ("zoh", 100.0, 1.2133): ((0.0106, 0.0916, 0.3749, -0.3007), (0.0331, 1.0666, -0.2724)),
}


def thesis_point(speed, rho, omega_a=THESIS_OMEGA_A, **changes):
    return PlantPoint(**{**LYNX, **changes}, speed=speed, density=rho, omega_a=omega_a)


def design(point, method, dt=THESIS_DT):
    return lqi_gain(*discretise(*augment(*lqi_plant(point)), dt, method), THESIS_Q, THESIS_R)


def reference_matrix(yaw, roll):
    """The (3, 11) gain docs/gnc.md lists, zero where it lists nothing."""
    k = np.zeros((3, 11))
    k[0, list(CHANNELS[0])] = yaw
    k[1, list(CHANNELS[1])] = (-yaw[0], *yaw[1:])
    k[2, list(CHANNELS[2])] = roll
    return k


def thesis_rhs(x, delta_cmd, speed, rho, c=LYNX, omega_a=THESIS_OMEGA_A):
    """ẋ of the nonlinear lateral rigid body with docs/lynx.md's dimensional force and moment (q̄ = ½ρV²,
    q_v = ½ρV; force damping q_v·S·d·C·ω, moment damping q_v·S·d·(d/2)·C·ω), axial speed held."""
    v, w, p, q, r, u_y, u_p, u_r = x
    s, d, m = c["area"], c["diameter"], c["mass"]
    airspeed = math.sqrt(speed**2 + v**2 + w**2)
    alpha, beta = math.atan2(w, speed), math.asin(v / airspeed)
    qbar, q_v = 0.5 * rho * airspeed**2, 0.5 * rho * airspeed
    cy = c["cy_beta"] * beta + c["cy_delta"] * u_y
    cn = c["cn_alpha"] * alpha + c["cn_delta"] * u_p
    f_y = qbar * s * cy + q_v * s * d * c["cy_r"] * r
    f_z = -qbar * s * cn - q_v * s * d * c["cn_q"] * q
    cl, cm = c["cl_delta"] * u_r, c["cm_alpha"] * alpha + c["cm_delta"] * u_p
    cn_yaw = c["cn_yaw_beta"] * beta + c["cn_yaw_delta"] * u_y
    damping = np.array([c["cl_p"] * p, c["cm_q"] * q, c["cn_r"] * r])
    moment = qbar * s * d * np.array([cl, cm, cn_yaw]) + q_v * s * d * (d / 2.0) * damping
    inertia = np.array([c["ixx"], c["iyy"], c["iyy"]])
    omega = np.array([p, q, r])
    rates_dot = (moment - np.cross(omega, inertia * omega)) / inertia
    return np.array([
        -r * speed + p * w + f_y / m, q * speed - p * v + f_z / m, *rates_dot,
        *(omega_a * (np.asarray(delta_cmd) - np.array([u_y, u_p, u_r]))),
    ])


def test_plant_is_the_jacobian_of_the_thesis_forces():
    """A, B against central differences of docs/lynx.md's dimensional forces: pins the damping conventions
    (force per ω·d/V, moment per ω·d/(2V)) and the kinematic −u r, +u q terms."""
    speed, rho, h = 150.0, 1.1, 1e-6
    a, b = lqi_plant(thesis_point(speed, rho))
    x0, d0 = np.zeros(8), np.zeros(3)
    jac_x = np.column_stack([(thesis_rhs(x0 + h * e, d0, speed, rho) - thesis_rhs(x0 - h * e, d0, speed, rho)) / (2 * h)
                             for e in np.eye(8)])
    jac_u = np.column_stack([(thesis_rhs(x0, d0 + h * e, speed, rho) - thesis_rhs(x0, d0 - h * e, speed, rho)) / (2 * h)
                             for e in np.eye(3)])
    # Central differences: truncation O(h²)·(cubic terms of atan/asin) ~ 1e-12 relative, rounding
    # ε·|f|/h ~ 1e-10·|f| with |f| up to ~1e3: 1e-6 absolute on entries up to ~2e3 is loose by 10×.
    np.testing.assert_allclose(a, jac_x, rtol=1e-8, atol=1e-6)
    np.testing.assert_allclose(b, jac_u, rtol=1e-8, atol=1e-6)


def test_augment_appends_the_negative_rate_integrators():
    a, b = augment(*lqi_plant(thesis_point(100.0, 1.2)))
    assert a.shape == (11, 11) and b.shape == (11, 3)
    expected = np.zeros((3, 11))
    expected[[0, 1, 2], [2, 3, 4]] = -1.0
    np.testing.assert_array_equal(a[8:], expected)
    np.testing.assert_array_equal(a[:8, 8:], 0.0)
    np.testing.assert_array_equal(b[8:], 0.0)


def test_augment_scales_the_integrators_by_their_gains():
    a, b = augment(*lqi_plant(thesis_point(100.0, 1.2)), (1.0, 12.0, 7.5))
    expected = np.zeros((3, 11))
    expected[[0, 1, 2], [2, 3, 4]] = -1.0, -12.0, -7.5
    np.testing.assert_array_equal(a[8:], expected)


def flight_step(a, b, gain, integrator_gain, dt, z):
    """One control period of the flight's own code on z = [x; e] (e before the step), ω_cmd = 0: the integrators
    stepped by ``guidance.integrate_errors``, u by ``control.lqi_command`` on the stepped ones, the plant over
    dt by scipy.signal's zero-order hold."""
    from rocketmc.gnc.control import lqi_command
    from rocketmc.gnc.guidance import integrate_errors
    from rocketmc.math import Vec3

    x, e = z[:8], z[8:]
    rates, zero = Vec3(*map(float, x[2:5])), Vec3(0.0, 0.0, 0.0)
    stepped = integrate_errors(Vec3(*map(float, e)), zero, rates, dt, True, Vec3(*integrator_gain))
    stepped = np.array([float(v) for v in stepped])
    u = np.array([float(v) for v in lqi_command(gain.ravel(), (*x, *stepped))])
    ad, bd, *_ = scipy.signal.cont2discrete((a, b, np.eye(8), np.zeros((8, 3))), dt, method="zoh")
    return np.concatenate([ad @ x + bd @ u, stepped])


def test_flown_loop_against_the_flights_own_step():
    """Each column of ``flown_loop`` is one period of the flight's own integrator step and command (JAX, float64
    here) from a unit state, through an independent ZOH: equal to rounding."""
    a, b = lqi_plant(thesis_point(100.0, 1.2133))
    gain = design(thesis_point(100.0, 1.2133), "zoh").gain
    loop = flown_loop(a, b, gain, (1.0, 12.0, 12.0), THESIS_DT)
    columns = np.column_stack([flight_step(a, b, gain, (1.0, 12.0, 12.0), THESIS_DT, z) for z in np.eye(11)])
    # Entries ≲ 1e1, two ZOH codes and the flight's sums in another order: rounding ~1e-14.
    np.testing.assert_allclose(loop, columns, rtol=0, atol=1e-12)


def test_flown_loop_with_the_integrator_gain_it_was_designed_for():
    """k_int = 1 designed, 1 flown: the flown loop's spectral radius is the designed one's to the integrator
    discretisation's half step (the thesis's 0.99495 at 100 m/s); the same gains flown with the thesis's 12 on pitch
    and yaw are not (roll at 12 even unstable: 1.089); designed with 12, flown with 12, they agree again."""
    a, b = lqi_plant(thesis_point(100.0, 1.2133))
    designed = design(thesis_point(100.0, 1.2133), "zoh")
    radius = lambda gain, k_int: np.abs(np.linalg.eigvals(flown_loop(a, b, gain, k_int, THESIS_DT))).max()  # noqa: E731
    assert radius(designed.gain, (1.0, 1.0, 1.0)) == pytest.approx(designed.spectral_radius, abs=1e-4)
    assert radius(designed.gain, (12.0, 12.0, 12.0)) > 1.0
    assert abs(radius(designed.gain, (1.0, 12.0, 12.0)) - designed.spectral_radius) > 1e-2
    flown_12 = lqi_gain(*discretise(*augment(a, b, (1.0, 12.0, 12.0)), THESIS_DT, "zoh"), THESIS_Q, THESIS_R)
    assert radius(flown_12.gain, (1.0, 12.0, 12.0)) == pytest.approx(flown_12.spectral_radius, abs=1e-4)


def test_zoh_matches_scipy_signal():
    a, b = augment(*lqi_plant(thesis_point(200.0, 1.1336)))
    ad, bd = discretise(a, b, THESIS_DT, "zoh")
    ad_ref, bd_ref, *_ = scipy.signal.cont2discrete((a, b, np.eye(11), np.zeros((11, 3))), THESIS_DT, method="zoh")
    # The same block exponential by another code path: agreement to rounding of entries ≲ 1e1.
    np.testing.assert_allclose(ad, ad_ref, rtol=1e-12, atol=1e-13)
    np.testing.assert_allclose(bd, bd_ref, rtol=1e-12, atol=1e-13)


def test_euler_is_first_order_in_dt_against_zoh():
    a, b = augment(*lqi_plant(thesis_point(100.0, 1.2133)))
    errors = []
    for dt in (0.004, 0.002):
        ad_e, bd_e = discretise(a, b, dt, "euler")
        ad_z, bd_z = discretise(a, b, dt, "zoh")
        np.testing.assert_array_equal(ad_e, np.eye(11) + a * dt)
        errors.append(np.abs(ad_e - ad_z).max() + np.abs(bd_e - bd_z).max())
    # The one-step difference is ½A²dt² + O(dt³): halving dt divides it by 4 (± the dt³ term, ‖A‖dt ≤ 0.05).
    assert errors[0] / errors[1] == pytest.approx(4.0, rel=0.1)


def test_unknown_discretisation_is_refused():
    with pytest.raises(ValueError, match="'tustin'"):
        discretise(np.eye(2), np.ones((2, 1)), 0.02, "tustin")


@pytest.mark.parametrize(("method", "speed", "rho"), list(REFERENCES))
def test_reference_gains_of_gnc_md(method, speed, rho):
    k = design(thesis_point(speed, rho), method).gain
    expected = reference_matrix(*REFERENCES[method, speed, rho])
    listed = expected != 0.0
    # Absolute 1e-3 on the 4-decimal references: they were printed to ±5e-5 and computed with
    # ω_a = 13 rad/s rounded (not 1/0.0769 = 13.0039), which moves the actuator gains by up to 5e-4
    # (test_references_used_the_rounded_servo_bandwidth pins that at 1e-4).
    np.testing.assert_allclose(k[listed], expected[listed], rtol=0, atol=1e-3)
    # Unlisted entries are structurally zero (decoupled channels): only DARE rounding, ~1e-14 on |K| ≲ 2.
    np.testing.assert_allclose(k[~listed], 0.0, atol=1e-12)


@pytest.mark.parametrize(("method", "speed", "rho"), list(REFERENCES))
def test_references_used_the_rounded_servo_bandwidth(method, speed, rho):
    """With ω_a = 13 rad/s exactly, docs/gnc.md's figures are reproduced to their rounding; with 1/0.0769
    they are not (up to 5e-4 off), so this is where the references' small offsets come from."""
    k = design(thesis_point(speed, rho, omega_a=13.0), method).gain
    expected = reference_matrix(*REFERENCES[method, speed, rho])
    listed = expected != 0.0
    # 5e-5 from the 4-decimal print, plus the quoted ρ's own rounding (±5e-5 kg/m³ moves the largest
    # gain, 1.46 at 200 m/s, by ≤ 4e-5): 1e-4. The true ω_a fails this by 5×.
    np.testing.assert_allclose(k[listed], expected[listed], rtol=0, atol=1e-4)


@pytest.mark.parametrize("method", ["euler", "zoh"])
def test_spectral_radius_of_gnc_md(method):
    # docs/gnc.md prints 0.99495 (5 decimals, ±5e-6) for both methods at 100 m/s.
    assert design(thesis_point(100.0, 1.2133), method).spectral_radius == pytest.approx(0.99495, abs=1e-5)


@pytest.mark.parametrize("method", ["euler", "zoh"])
def test_pitch_mirrors_yaw(method):
    # The thesis coefficients are axisymmetric (CN_α = −CY_β, Cm_α = −Cn_β, ...): the pitch channel is
    # the yaw channel with w → −w, so the two rows agree to rounding.
    k = design(thesis_point(200.0, 1.1336), method).gain
    yaw, pitch = k[0, list(CHANNELS[0])], k[1, list(CHANNELS[1])]
    np.testing.assert_allclose(pitch, yaw * np.array([-1.0, 1.0, 1.0, 1.0]), rtol=1e-10)


def riccati_iteration(ad, bd, q, r, tol=1e-14, max_steps=50_000):
    """P of the Riccati difference equation iterated from P = Q to a fixed point."""
    p = q.copy()
    for _ in range(max_steps):
        bt_p = bd.T @ p
        p_next = ad.T @ p @ ad - ad.T @ p @ bd @ np.linalg.solve(r + bt_p @ bd, bt_p @ ad) + q
        p_next = 0.5 * (p_next + p_next.T)
        if np.linalg.norm(p_next - p) <= tol * np.linalg.norm(p_next):
            return p_next
        p = p_next
    raise AssertionError("Riccati iteration did not converge")


@pytest.mark.parametrize(("method", "speed", "rho"), [("zoh", 100.0, 1.2133), ("euler", 200.0, 1.1336)])
def test_dare_against_riccati_iteration(method, speed, rho):
    ad, bd = discretise(*augment(*lqi_plant(thesis_point(speed, rho))), THESIS_DT, method)
    result = lqi_gain(ad, bd, THESIS_Q, THESIS_R)
    # scipy's Schur solution satisfies the DARE to rounding (measured ~1e-14 relative).
    assert result.residual < 1e-9
    p = riccati_iteration(ad, bd, THESIS_Q, THESIS_R)
    k = np.linalg.solve(THESIS_R + bd.T @ p @ bd, bd.T @ p @ ad)
    # The iteration converges like ρ_cl^(2n) (ρ_cl ≈ 0.995): stopped at a 1e-14 relative step its P
    # is within ~1e-12 relative of the fixed point, far inside 1e-8 on |K| ≲ 2.
    np.testing.assert_allclose(result.gain, k, rtol=0, atol=1e-8)
    np.testing.assert_allclose(result.riccati, p, rtol=1e-8, atol=1e-8 * np.abs(p).max())


def test_weights_must_be_admissible():
    ad, bd = discretise(*augment(*lqi_plant(thesis_point(100.0, 1.2))), THESIS_DT, "zoh")
    q_negative = THESIS_Q.copy()
    q_negative[3, 3] = -5.0
    with pytest.raises(ValueError, match="at the design point: Q must be positive semi-definite"):
        lqi_gain(ad, bd, q_negative, THESIS_R)
    with pytest.raises(ValueError, match="symmetric"):
        lqi_gain(ad, bd, THESIS_Q + np.eye(11, k=1), THESIS_R)


def lynx_at(speed, altitude):
    """The thesis plant at a grid point, ρ from the ISA."""
    return thesis_point(speed, density(altitude))


@pytest.mark.parametrize("method", ["euler", "zoh"])
def test_gain_schedule_over_a_small_grid(method):
    speeds, altitudes = (60.0, 150.0, 250.0), (0.0, 1500.0)
    schedule = gain_schedule(lynx_at, speeds, altitudes, method=method)
    assert schedule.gains.shape == (3, 2, 3, 11)
    assert schedule.spectral_radius.shape == schedule.residual.shape == schedule.flown_radius.shape == (3, 2)
    assert np.all(schedule.spectral_radius < 1.0) and np.all(schedule.flown_radius < 1.0)
    assert np.all(schedule.residual < 1e-9)  # as in test_dare_against_riccati_iteration
    np.testing.assert_array_equal(schedule.speeds, speeds)
    # Each cell is the single-point design at that speed and ISA density (same code path: bit-equal).
    np.testing.assert_array_equal(schedule.gains[1, 1], design(thesis_point(150.0, density(1500.0)), method).gain)
    assert density(1500.0) == pytest.approx(1.0581, abs=1e-4)  # ISA table, 1500 m


@pytest.mark.filterwarnings("ignore:invalid value encountered:RuntimeWarning")  # scipy, on the singular pencil
def test_schedule_names_a_point_with_no_control_authority():
    # At zero speed the canards have no authority and the rate integrators cannot be stabilised.
    with pytest.raises(ValueError, match=r"^LQI design at speed 0 m/s, altitude 0 m: no stabilising DARE solution"):
        gain_schedule(lynx_at, (0.0, 100.0, 200.0), (0.0, 1000.0))


def test_schedule_names_an_interior_failing_point():
    def stalled_at_200_1000(speed, altitude):
        """No pitch/yaw canard authority at one interior point: e_q, e_r stay on the unit circle."""
        point = lynx_at(speed, altitude)
        if (speed, altitude) == (200.0, 1000.0):
            point = point._replace(cy_delta=0.0, cn_delta=0.0, cm_delta=0.0, cn_yaw_delta=0.0)
        return point

    with pytest.raises(ValueError, match=r"^LQI design at speed 200 m/s, altitude 1000 m: no stabilising DARE solution"):
        gain_schedule(stalled_at_200_1000, (100.0, 200.0, 300.0), (0.0, 1000.0))


def test_a_returned_solution_that_does_not_stabilise_is_refused(monkeypatch):
    # scipy returns a P (here zero: K = 0) whose closed loop is the open loop, unstable: refused with its radius.
    # (On a pencil with eigenvalues on the unit circle scipy raises or returns such a P, by LAPACK's rounding.)
    monkeypatch.setattr(scipy.linalg, "solve_discrete_are", lambda a, b, q, r: np.zeros_like(a))
    ad, bd = np.array([[1.5]]), np.array([[1.0]])
    with pytest.raises(ValueError, match=r"^LQI design at here: no stabilising DARE solution \(the closed loop's "
                                         r"spectral radius 1.5 is not below 1\)$"):
        lqi_gain(ad, bd, np.eye(1), np.eye(1), "here")


@pytest.mark.parametrize("speeds", [(100.0, 50.0, 200.0), (), ((100.0, 200.0),)])
def test_schedule_grid_must_increase(speeds):
    with pytest.raises(ValueError, match="speeds must be a non-empty, strictly increasing 1-D grid"):
        gain_schedule(lynx_at, speeds, (0.0,))

"""Flights of the Lynx with its canards deflected, open loop, against closed forms.

The canards hold constant fin deflections δ1..δ4 = ``allocate(yaw, pitch, roll)`` from the launch
on (``fly``'s ``canard_command``). The expectations come from the model's own linear derivatives
at the flight's Mach number and altitude (central differences of ``table_coefficients`` at zero
angles, deflections and rates, the definition ``simplify`` and ``linear_derivatives`` use, here
at single points since ``simplify`` of the whole grid costs ~15 s):

* roll: the body's roll rate settles where the rolling moment vanishes,
  Cl0 + Cl_δ·u + Cl_p·p·d/(2V) = 0, i.e. p_ss = −(Cl0 + Cl_δ·u)/Cl_p · 2V/d, with the time
  constant τ = 4·Ixx/(−Cl_p·ρ·V·S·d²) (0.3-0.6 s in the coast); there V falls, and p lags p_ss
  by τ·dp_ss/dt to first order;
* pitch: the rocket trims where Cm_α·α + Cm_δ·u + Cm_q·q·d/(2V) = 0 (about the CG, which after
  burnout is the Lynx's moment reference; q is the pitch rate of the turning flight path), and
  its normal force turns the flight path toward the body's −z, which at launch points up and
  back: a positive pitch command steepens the flight path.

These check the flight's dynamics (the deflections reaching the model, the wrench's scaling with
q̄·S·d, the inertia, the rate non-dimensionalisation, the signs), not the aerodynamic tables
themselves: an error inside ``table_coefficients`` moves the flight and the expectation alike
(tests/aero covers the tables).

The flights are calm (no wind, no turbulence: same pytree, zero speeds and intensities), so the
air-relative velocity is v_n. One compiled function flies every command (the command is its
argument); a second one flies the default, neutral path for the bit-for-bit check.
"""

from __future__ import annotations

import dataclasses

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from rocketmc.aero import AirData
from rocketmc.aero.canards import allocate
from rocketmc.aero.model import table_coefficients
from rocketmc.campaign.runner import sim_settings
from rocketmc.env import isa
from rocketmc.math import Vec3
from rocketmc.sim.flight import fly
from rocketmc.sim.loads import mass_properties

N_PERIODS = 500  # 10 s at 0.02 s: rail, burn (to ~3.6 s) and 6 s of coast, far below apogee (~25 s)
U = 0.02  # virtual command [rad] (1.1°): small enough for the linear model, large against Cl0 = −0.03


def calm(p):
    """The same flight without wind and turbulence (same structure, zero speeds and intensities)."""
    env = p.environment
    t, w = env.turbulence, env.wind
    turbulence = dataclasses.replace(t, severity=t.severity * 0.0, w20_mps=t.w20_mps * 0.0)
    wind = dataclasses.replace(w, north_mps=w.north_mps * 0.0, east_mps=w.east_mps * 0.0)
    return dataclasses.replace(p, environment=dataclasses.replace(env, turbulence=turbulence, wind=wind))


def without_cl0(p):
    """The same rocket without the fin-misalignment roll offset: a planar flight until commanded."""
    aero = dataclasses.replace(p.rocket.aero, cl0=jnp.zeros_like(p.rocket.aero.cl0))
    return dataclasses.replace(p, rocket=dataclasses.replace(p.rocket, aero=aero))


def host(tree):
    return jax.tree_util.tree_map(np.asarray, tree)


@pytest.fixture(scope="module")
def settings(lynx_campaign):
    """The campaign's, at the GNC's 20 ms periods (the canards are a controller's actuators; lynx_nominal's own
    open-loop periods are 40 ms)."""
    settings = sim_settings(lynx_campaign)
    return dataclasses.replace(settings, open_loop_dt_s=settings.control_dt_s)


@pytest.fixture(scope="module")
def fly_command(settings):
    """(params, four deflections) -> trajectory, the deflections held for the whole flight."""
    fn = jax.jit(lambda p, deflections: fly(p, settings, N_PERIODS, lambda t: deflections)[1])
    return lambda p, deflections: host(fn(p, jnp.asarray(deflections, dtype=float)))


@pytest.fixture(scope="module")
def roll_flights(fly_command, lynx_params):
    p = calm(lynx_params)
    return p, {u: fly_command(p, allocate(0.0, 0.0, u)) for u in (-U, 0.0, U)}


@pytest.fixture(scope="module")
def pitch_flights(fly_command, lynx_params):
    p = without_cl0(calm(lynx_params))
    return p, {u: fly_command(p, allocate(0.0, u, 0.0)) for u in (-U, 0.0, U)}


@jax.jit
def _derivatives(aero, mach, altitude_msl):
    unit = dataclasses.replace(aero, drag_scale=jnp.ones_like(aero.drag_scale), cl0=jnp.zeros_like(aero.cl0))
    roll, pitch = jnp.asarray(allocate(0.0, 0.0, 1.0)), jnp.asarray(allocate(0.0, 1.0, 0.0))
    h = 1e-4

    def at(m, z, alpha=0.0, p_hat=0.0, q_hat=0.0, deflections=jnp.zeros(4)):
        air = AirData(1.0, alpha, 0.0, m, 0.5, 1.0, z)
        return table_coefficients(unit, air, Vec3(p_hat, q_hat, 0.0), unit.moment_ref_x_m, deflections)[0]

    def one(m, z):
        cl_delta = (at(m, z, deflections=h * roll).cl - at(m, z, deflections=-h * roll).cl) / (2 * h)
        cl_p = at(m, z).cl_p + (at(m, z, p_hat=h).cl - at(m, z, p_hat=-h).cl) / (2 * h)  # body + canard incidence
        cm_delta = (at(m, z, deflections=h * pitch).cm - at(m, z, deflections=-h * pitch).cm) / (2 * h)
        cm_alpha = (at(m, z, alpha=h).cm - at(m, z, alpha=-h).cm) / (2 * h)
        cm_q = at(m, z).cm_q + (at(m, z, q_hat=h).cm - at(m, z, q_hat=-h).cm) / (2 * h)  # body + canard incidence
        return jnp.stack([cl_delta, cl_p, cm_delta, cm_alpha, cm_q])

    return jax.vmap(one)(mach, altitude_msl).T


def derivatives(aero, mach, altitude_msl):
    """Cl_δ (roll command), Cl_p (per p·d/(2V)), Cm_δ (pitch command), Cm_α, Cm_q (per q·d/(2V)) of the
    interpolated model at each (Mach, altitude), by central differences at zero angles, rates and
    deflections, as ``simplify`` takes them (the mean slope of the table cells around zero).
    Always called on whole trajectories (one shape: one compilation)."""
    assert np.shape(mach) == (N_PERIODS,)
    return np.asarray(_derivatives(aero, jnp.asarray(mach), jnp.asarray(altitude_msl)))


def coast(traj):
    """Mask of the coast samples from 0.5 s after burnout (thrust tail-off and its transient over)."""
    burnout = float(traj.events.burnout_time[-1])
    assert 3.0 < burnout < 4.5  # the L1350 burns ~3.1 s after a 0.5 s ignition delay
    return traj.t > burnout + 0.5


def air_along(p, traj):
    """Airspeed [m/s], Mach, density [kg/m³] and altitude [m MSL] along a calm trajectory."""
    v = traj.body.v_n
    speed = np.sqrt(v.x**2 + v.y**2 + v.z**2)
    altitude = float(p.environment.site_altitude_m) - traj.body.r_n.z
    atmosphere = isa(jnp.asarray(altitude))
    return speed, speed / np.asarray(atmosphere.speed_of_sound), np.asarray(atmosphere.density), altitude


# ------------------------------------------------------------------------------------------ tests


def test_zero_command_is_the_neutral_flight_bit_for_bit(settings, fly_command, lynx_params):
    """Zero deflections through ``canard_command`` fly the default (neutral) path exactly: the
    nominal flight with its wind and turbulence, every state and event of every period."""
    neutral = host(jax.jit(lambda p: fly(p, settings, N_PERIODS)[1])(lynx_params))
    zero = fly_command(lynx_params, np.zeros(4))
    for a, b in zip(jax.tree_util.tree_leaves(neutral), jax.tree_util.tree_leaves(zero)):
        np.testing.assert_array_equal(a, b)
    assert float(np.max(np.abs(neutral.body.omega_b.x))) > 1.0  # a real flight (rolling under Cl0), not zeros


def test_roll_command_rolls_with_the_sign_of_cl_delta(roll_flights):
    """After the rail (from 1 s, ~40 m/s and up) the roll rate added by ±u has the sign of Cl_δ·u
    (Cl_δ > 0: the thesis's sign), and antisymmetric commands add opposite rates: equal magnitudes
    within 2 % (the panel table is multilinear in δ, so the slopes on either side of zero may
    differ; measured 0.1-0.5 %)."""
    p, flights = roll_flights
    traj = flights[0.0]
    speed, mach, _, altitude = air_along(p, traj)
    cl_delta = derivatives(p.rocket.aero, mach, altitude)[0]
    assert np.all(cl_delta > 0)
    after_rail = traj.t >= 1.0
    up = flights[U].body.omega_b.x - traj.body.omega_b.x
    down = flights[-U].body.omega_b.x - traj.body.omega_b.x
    assert np.all(up[after_rail] > 0) and np.all(down[after_rail] < 0)
    np.testing.assert_allclose(-down[after_rail], up[after_rail], rtol=0.02)


def test_roll_rate_follows_the_steady_state(roll_flights):
    """In the coast the roll rate of u ∈ {−U, 0, U} matches p_ss − τ·dp_ss/dt within 2 % (measured
    within 0.9 %; the first-order lag correction itself is 2-7 %, so a rate ignoring the inertia
    or a wrong Cl_p fails; left over are its second order and the Mach dependence of Cl_p). As
    the rocket decelerates, |p| stays above |p_ss|: it lags the falling steady state. The neutral
    flight rolls too, at −Cl0/Cl_p·2V/d (Cl0 = −0.03 of fin misalignment)."""
    p, flights = roll_flights
    aero = p.rocket.aero
    d, area, cl0 = float(aero.reference_length_m), float(aero.reference_area_m2), float(aero.cl0)
    traj = flights[0.0]
    t = traj.t
    in_coast = coast(traj)
    speed, mach, density, altitude = air_along(p, traj)
    cl_delta, cl_p, *_ = derivatives(aero, mach, altitude)
    ixx = np.asarray(mass_properties(p, jnp.asarray(t)).ixx)
    tau = 4.0 * ixx[in_coast] / (-cl_p[in_coast] * density[in_coast] * speed[in_coast] * area * d**2)
    assert np.all((tau > 0.1) & (tau < 1.0))  # fast against the 6 s of coast
    for u, flight in flights.items():
        # the same speed along each flight within 0.3 % (measured 0.1 % at 10 s): the canards' drag is
        # quadratic in δ, so the steady states may be taken on the neutral flight's speed
        np.testing.assert_allclose(air_along(p, flight)[0][in_coast], speed[in_coast], rtol=3e-3)
        p_ss = -(cl0 + cl_delta * u) / cl_p * 2.0 * speed / d
        roll_rate = flight.body.omega_b.x[in_coast]
        expected = p_ss[in_coast] - tau * np.gradient(p_ss, t)[in_coast]
        np.testing.assert_allclose(roll_rate, expected, rtol=0.02, err_msg=f"u = {u}")
        assert np.all(np.abs(roll_rate) > np.abs(p_ss[in_coast])), u


def test_pitch_command_turns_the_flight_path(pitch_flights):
    """Without Cl0 the calm flights neither roll nor leave their launch plane (out-of-plane speed
    below 1e-6 of the speed: no roll, no yaw command). A positive pitch command steepens the
    flight-path angle in that plane, γ = atan2(−v_d, v·ĥ), a negative one flattens it, by more
    than 5° from 6 s on (measured 14.6° at 6 s) and by the same amount within 5 % (gravity turns
    both the same way; measured 0.3-2 %). In the coast the angle of attack is the trim
    α = −(Cm_δ·u + Cm_q·q·d/(2V))/Cm_α with the flight's own pitch rate q within 3 % (measured
    0.6-1.7 %: the short-period transient and the Mach dependence; without the damping term the
    error is 7-18 %)."""
    p, flights = pitch_flights
    rail = p.launch.rail_direction_n
    along = np.array([float(rail.x), float(rail.y)]) / np.hypot(float(rail.x), float(rail.y))  # the rail's azimuth
    across = np.array([-along[1], along[0]])
    d = float(p.rocket.aero.reference_length_m)
    traj = flights[0.0]
    in_coast = coast(traj)
    speed, mach, _, altitude = air_along(p, traj)
    _, _, cm_delta, cm_alpha, cm_q = derivatives(p.rocket.aero, mach, altitude)
    gamma = {}
    for u, flight in flights.items():
        v = flight.body.v_n
        horizontal = np.stack([v.x, v.y], axis=-1)
        assert np.all(np.abs(horizontal @ across) <= 1e-6 * speed), u
        assert np.all(np.abs(flight.body.omega_b.x) < 1e-9), u
        gamma[u] = np.arctan2(-v.z, horizontal @ along)
        if u:
            vb = _rotate_inverse(flight.body.q_nb, (v.x, v.y, v.z))  # the air-relative velocity in the body frame
            alpha = np.arctan2(vb[2], vb[0])[in_coast]
            q_hat = flight.body.omega_b.y[in_coast] * d / (2.0 * speed[in_coast])
            trim = -(cm_delta[in_coast] * u + cm_q[in_coast] * q_hat) / cm_alpha[in_coast]
            assert np.all(np.sign(trim) == np.sign(u))  # Cm_δ > 0 and Cm_α < 0: the thesis's signs
            np.testing.assert_allclose(alpha, trim, rtol=0.03, err_msg=f"u = {u}")
    late = traj.t >= 6.0
    steeper, flatter = gamma[U][late] - gamma[0.0][late], gamma[-U][late] - gamma[0.0][late]
    assert np.all(steeper > np.deg2rad(5.0)) and np.all(flatter < -np.deg2rad(5.0))
    np.testing.assert_allclose(-flatter, steeper, rtol=0.05)


def _rotate_inverse(q, v):
    """q* ⊗ v ⊗ q for host arrays (a world vector in the body frame when q = q_nb)."""
    w, x, y, z = q
    x, y, z = -x, -y, -z
    vx, vy, vz = v
    tx, ty, tz = 2 * (y * vz - z * vy), 2 * (z * vx - x * vz), 2 * (x * vy - y * vx)
    return vx + w * tx + (y * tz - z * ty), vy + w * ty + (z * tx - x * tz), vz + w * tz + (x * ty - y * tx)

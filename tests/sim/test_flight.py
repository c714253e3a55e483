"""Whole flights of the Lynx against closed forms, and the properties of the flight loop.

Compilation dominates the cost (~15 s per compiled flight function on CPU), so the module
compiles four and reuses them: ``fly`` and ``simulate_one`` with the campaign's settings (every
parameter variant below keeps the same pytree structure: no-aero and no-canopy flights zero the
coefficients instead of removing fields or parachutes), the vmapped ``realization``, and a
short-``max_time_s`` ``simulate_one``.
"""

from __future__ import annotations

import dataclasses

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from scipy.integrate import solve_ivp, trapezoid

from rocketmc.campaign.model import flight_params
from rocketmc.campaign.runner import realization, sim_settings
from rocketmc.campaign.sampling import realization_key, sample_dispersions
from rocketmc.dynamics import RigidBodyState
from rocketmc.env import G0, isa
from rocketmc.math import Vec3
from rocketmc.math.table import Table
from rocketmc.sim.events import rail_start_n, rail_travel_m
from rocketmc.sim.flight import (
    EVENT_OVERSHOOT, POINT_MASS_H_RATE, POINT_MASS_MAX_S, fly, initial_state, regular_period_s, simulate_one,
)
from rocketmc.sim.loads import derivatives, mass_properties
from rocketmc.sim.outputs import METRICS, flight_summary, metric
from rocketmc.sim.params import SimSettings
from rocketmc.sim.state import Status

N_PERIODS = 3000  # periods flown by `fly`: past every landing (~800: 0.04 s up, up to 5 s under canopy)


# ----------------------------------------------------------------------------- parameter variants


def still(p):
    """The same flight without turbulence (same structure, zero intensities): the mean wind only."""
    t = p.environment.turbulence
    turbulence = dataclasses.replace(t, severity=t.severity * 0.0, w20_mps=t.w20_mps * 0.0)
    return dataclasses.replace(p, environment=dataclasses.replace(p.environment, turbulence=turbulence))


def calm(p):
    """The same flight with no wind and no turbulence (same structure, zero speeds and intensities)."""
    w = still(p).environment.wind
    wind = dataclasses.replace(w, north_mps=w.north_mps * 0.0, east_mps=w.east_mps * 0.0)
    return dataclasses.replace(p, environment=dataclasses.replace(still(p).environment, wind=wind))


def vacuum(p):
    """No aerodynamic force or moment and zero canopy drag: thrust and gravity only."""
    is_table = lambda x: isinstance(x, Table)  # noqa: E731
    zero = lambda x: dataclasses.replace(x, values=x.values * 0.0) if is_table(x) else x  # noqa: E731
    aero = dataclasses.replace(jax.tree_util.tree_map(zero, p.rocket.aero, is_leaf=is_table), cl0=0.0)
    chutes = tuple(dataclasses.replace(c, cd_s_m2=c.cd_s_m2 * 0.0) for c in p.rocket.parachutes)
    rocket = dataclasses.replace(
        p.rocket, aero=aero, parachutes=chutes, canopy_cl_p=p.rocket.canopy_cl_p * 0.0
    )
    return dataclasses.replace(p, rocket=rocket)


def host(tree):
    return jax.tree_util.tree_map(np.asarray, tree)


def floats(summary):
    return {k: float(v) for k, v in summary.items()}


# ------------------------------------------------------------------------------------ fixtures


@pytest.fixture(scope="module")
def settings(lynx_campaign):
    return sim_settings(lynx_campaign)


@pytest.fixture(scope="module")
def period_s(windy_flight, settings):
    """The open-loop flights' regular period [s] (``open_loop_dt_s``)."""
    return regular_period_s(windy_flight[0], settings)


@pytest.fixture(scope="module")
def fly_fn(settings):
    return jax.jit(lambda p: fly(p, settings, N_PERIODS))


@pytest.fixture(scope="module")
def simulate_fn(settings):
    return jax.jit(lambda p: simulate_one(p, settings))


def _fly(fly_fn, params):
    final, traj = fly_fn(params)
    summary, status = flight_summary(params, final)
    return params, host(traj), floats(summary), int(status)


@pytest.fixture(scope="module")
def calm_flight(settings, lynx_params):
    """The nominal flight without wind, its descent in 6 DOF throughout."""
    six_dof = dataclasses.replace(settings, point_mass_descent=False)
    return _fly(jax.jit(lambda p: fly(p, six_dof, N_PERIODS)), calm(lynx_params))


@pytest.fixture(scope="module")
def point_mass_calm_flight(fly_fn, lynx_params):
    return _fly(fly_fn, calm(lynx_params))


@pytest.fixture(scope="module")
def windy_flight(fly_fn, lynx_params):
    """The nominal flight in its layered wind, without turbulence."""
    return _fly(fly_fn, still(lynx_params))


@pytest.fixture(scope="module")
def vacuum_flight(fly_fn, simulate_fn, lynx_params):
    params = calm(vacuum(lynx_params))
    _, traj, _, _ = _fly(fly_fn, params)
    summary, status = simulate_fn(params)
    return params, traj, floats(summary), int(status)


def bracket(t, time):
    """Index j with t[j] < time <= t[j + 1] (the period in which an event happened)."""
    j = int(np.searchsorted(t, time, side="left")) - 1
    assert 0 <= j < len(t) - 1 and t[j] < time <= t[j + 1]
    return j


# ------------------------------------------------------------------------------ set-up checks


def test_launch_attitude_points_up_the_rail_and_nozzle_starts_at_the_pad(lynx_campaign, lynx_params):
    launch = lynx_params.launch
    nose = launch.q_nb0.rotate(Vec3(1.0, 0.0, 0.0))
    el, az = np.deg2rad(lynx_campaign.config.launch.elevation_deg), np.deg2rad(lynx_campaign.config.launch.azimuth_deg)
    expected = [np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), -np.sin(el)]
    np.testing.assert_allclose(np.asarray(nose.to_array()), expected, atol=1e-15)  # rounding of cos/sin
    np.testing.assert_allclose(np.asarray(launch.rail_direction_n.to_array()), expected, atol=1e-15)
    state = initial_state(lynx_params)
    cg_x = mass_properties(lynx_params, 0.0).cg_x
    nozzle = state.body.r_n + state.body.q_nb.rotate(Vec3(lynx_params.rocket.motor.nozzle_x_m - cg_x, 0.0, 0.0))
    np.testing.assert_allclose(np.asarray(nozzle.to_array()), 0.0, atol=1e-15)  # O(1 m) lengths: rounding
    np.testing.assert_array_equal(np.asarray(rail_start_n(lynx_params).to_array()), np.asarray(state.body.r_n.to_array()))
    assert float(state.t) == 0.0 and float(state.body.v_n.norm()) == 0.0


def test_vacuum_coast_right_hand_side_is_gravity(lynx_params):
    """After burnout and rail exit, the full right-hand side of a no-aero flight is (v, g ẑ, ½q⊗ω, 0)."""
    p = calm(vacuum(lynx_params))
    ev = initial_state(p).events
    ev = dataclasses.replace(ev, rail_exit_time=jnp.asarray(0.8))  # off the rail
    body = RigidBodyState(Vec3(10.0, -5.0, -900.0), Vec3(20.0, 30.0, -150.0), p.launch.q_nb0, Vec3(0.0, 0.0, 0.0))
    d, diag = derivatives(jnp.asarray(10.0), body, p, (0.0, 0.0, 0.0, 0.0), Vec3.zeros(), ev)
    np.testing.assert_array_equal(np.asarray(d.r_n.to_array()), [20.0, 30.0, -150.0])
    np.testing.assert_array_equal(np.asarray(d.v_n.to_array()), [0.0, 0.0, G0])  # exactly: all other terms are 0·x
    np.testing.assert_array_equal(np.asarray(d.omega_b.to_array()), 0.0)
    assert float(diag.mach) > 0.4  # the atmosphere is still there for the diagnostics (150 m/s)


# --------------------------------------------------------------------------- vacuum ballistic


def test_vacuum_flight_matches_the_parabola(vacuum_flight, settings):
    p, traj, s, status = vacuum_flight
    assert status == Status.OK
    t, r, v = traj.t, traj.body.r_n, traj.body.v_n
    t_bo = float(p.rocket.motor.ignition_time_s + p.rocket.motor.burn_time_s)  # 0.5 + 3.284 s
    assert s["burnout_time_s"] == pytest.approx(t_bo, abs=1e-12)  # t0 + ((t_bo − t0)/h)·h: rounding
    k0 = int(np.argmax(t > t_bo))  # first state after burnout: from here on gravity only
    t0, h0, climb0 = t[k0], -r.z[k0], -v.z[k0]
    north0, east0, vn, ve = r.x[k0], r.y[k0], v.x[k0], v.y[k0]

    # Apogee: RK4 integrates a quadratic exactly, the climb rate is linear in t (so its zero
    # crossing is exact) and the cubic Hermite altitude interpolant is exact on a parabola: only
    # rounding remains (values ~2000 m, ~1000 steps: ~1e-10 m).
    t_apogee = t0 + climb0 / G0
    assert s["apogee_time_s"] == pytest.approx(t_apogee, abs=1e-9)
    assert s["apogee_agl_m"] == pytest.approx(h0 + climb0**2 / (2 * G0), abs=1e-6)
    assert s["apogee_north_m"] == pytest.approx(north0 + vn * (t_apogee - t0), abs=1e-8)
    assert s["apogee_east_m"] == pytest.approx(east0 + ve * (t_apogee - t0), abs=1e-8)
    # The same closed form from the burnout event alone: apogee gain = ½ g (t_apogee − t_burnout)².
    # The burnout altitude is a linear interpolation across the 20 ms burnout step: error
    # ≤ |a| h²/8 ≈ 9.8 · 0.02² / 8 = 5e-4 m.
    gain = s["apogee_agl_m"] - s["burnout_altitude_agl_m"]
    assert gain == pytest.approx(0.5 * G0 * (s["apogee_time_s"] - t_bo) ** 2, abs=1e-3)

    # Every sampled state of the coast lies on the parabola (rounding only, measured 1.1e-10 m).
    fall = (climb0 + np.sqrt(climb0**2 + 2 * G0 * h0)) / G0  # alt(t0 + τ) = h0 + climb0 τ − ½ g τ² = 0
    t_impact = t0 + fall
    coast = (t >= t0) & (t < t_impact)
    tau = t[coast] - t0
    np.testing.assert_allclose(r.x[coast], north0 + vn * tau, rtol=0, atol=1e-8)
    np.testing.assert_allclose(r.y[coast], east0 + ve * tau, rtol=0, atol=1e-8)
    np.testing.assert_allclose(-r.z[coast], h0 + climb0 * tau - 0.5 * G0 * tau**2, rtol=0, atol=1e-8)

    # Impact: the crossing of altitude 0 is linearly interpolated over the period that contains it;
    # on a parabola that misplaces it by ≤ g h²/8 in altitude, i.e. ≤ g h²/(8 |v_z|) in time.
    j = bracket(t, s["impact_time_s"])
    h_step = t[j + 1] - t[j]
    assert h_step <= settings.descent_dt_s + 1e-12
    dt_bound = G0 * h_step**2 / (8 * abs(v.z[j])) + 1e-9  # + rounding; measured 6e-7 s of 2.4e-6 s
    assert s["impact_time_s"] == pytest.approx(t_impact, abs=dt_bound)
    assert s["impact_north_m"] == pytest.approx(north0 + vn * fall, abs=abs(vn) * dt_bound + 1e-8)
    assert s["impact_east_m"] == pytest.approx(east0 + ve * fall, abs=abs(ve) * dt_bound + 1e-8)
    # energy: v² = v0² + 2 g h0; the speed changes by ≤ g per second, so the misplaced crossing
    # time moves it by ≤ g·dt_bound (measured 6e-6 m/s)
    v_impact = np.sqrt(vn**2 + ve**2 + climb0**2 + 2 * G0 * h0)
    assert s["impact_speed_mps"] == pytest.approx(v_impact, abs=G0 * dt_bound + 1e-9)

    # No moment acts: after the rail the body neither rotates nor turns (ω stays exactly 0).
    after_rail = t > s["rail_exit_time_s"] + settings.control_dt_s
    np.testing.assert_array_equal(np.asarray(traj.body.omega_b.to_array())[after_rail], 0.0)
    q = np.asarray(traj.body.q_nb.to_array())[after_rail]
    np.testing.assert_allclose(q, np.broadcast_to(np.asarray(p.launch.q_nb0.to_array()), q.shape), atol=1e-15)


def test_vacuum_rail_exit_matches_the_rail_ode(vacuum_flight, settings):
    """On the rail without aerodynamics: s'' = F(t)/m(t) − g sin(elevation), no sliding back,
    integrated by scipy (DOP853, tight tolerances, restarted at every thrust-curve point)."""
    p, _, s, _ = vacuum_flight
    motor, rocket = p.rocket.motor, p.rocket
    sin_el = -float(p.launch.rail_direction_n.z)  # the rail's elevation (NED z is down)
    m_dry, m_prop0 = float(rocket.dry_mass_kg), float(motor.propellant_mass_kg)
    ignition = float(motor.ignition_time_s)
    curve_t, curve_f = np.asarray(motor.time_s), np.asarray(motor.thrust_n)
    total = trapezoid(curve_f, curve_t)

    def thrust_np(t):
        return np.interp(t - ignition, curve_t, curve_f) if 0.0 <= t - ignition <= curve_t[-1] else 0.0

    def mass_np(t):  # dry + propellant left, ṁ ∝ F: m_p = m_p0 (1 − ∫F/I_tot)
        tau = np.clip(t - ignition, 0.0, curve_t[-1])
        upto = curve_t <= tau
        knots_t = np.append(curve_t[upto], tau)
        burnt = trapezoid(np.interp(knots_t, curve_t, curve_f), knots_t)
        return m_dry + m_prop0 * (1.0 - burnt / total)

    def rhs(t, y):
        a = thrust_np(t) / mass_np(t) - G0 * sin_el
        return [y[1], a if (y[1] > 0.0 or a > 0.0) else 0.0]

    # the rear lug leaves the top of the rail after this travel of the nozzle from the pad
    travel = float(rail_travel_m(p))
    exit_event = lambda t, y: y[0] - travel  # noqa: E731
    exit_event.terminal = True
    stops = [ignition] + list(ignition + curve_t[1:])
    y, t0 = [0.0, 0.0], 0.0
    for t1 in stops:
        sol = solve_ivp(rhs, (t0, t1), y, method="DOP853", rtol=1e-12, atol=1e-12, events=exit_event)
        if sol.status == 1:
            t_exit, v_exit = sol.t_events[0][0], sol.y_events[0][0][1]
            break
        y, t0 = sol.y[:, -1], t1
    else:
        pytest.fail("the reference never left the rail")
    # The simulator finds the exit by linear interpolation inside a period while the rocket accelerates at
    # a ≈ 66 m/s²: ≤ a h²/(8 v) ≈ 1.7e-4 s at h = 20 ms, i.e. ≤ a·that ≈ 0.011 m/s; its periods end at the thrust
    # curve's points and just past the exit (``event_period``), but the first one holds liftoff (the rocket rests
    # until the thrust exceeds its weight along the rail: a kink ~3 ms after ignition). Measured: 2.6e-4 s and
    # 7.3e-4 m/s (2.0e-4 s and 6.3e-3 m/s with the kinks inside 20 ms steps). Tolerances: 5e-4 s and 0.02 m/s
    # (0.1 %).
    assert s["rail_exit_time_s"] == pytest.approx(t_exit, abs=5e-4)
    assert s["rail_exit_speed_mps"] == pytest.approx(v_exit, abs=0.02)
    assert float(motor.ignition_time_s) < s["rail_exit_time_s"] < s["burnout_time_s"]


# ----------------------------------------------------------------------------- canopy descent


@pytest.mark.parametrize("canopy", ["drogue", "main"])
def test_steady_descent_rate(calm_flight, point_mass_calm_flight, canopy):
    """Late under each canopy (no wind) the descent rate is the terminal speed sqrt(2 m g/(ρ Cd·S)),
    with ρ the ISA density at the altitude and m the dry mass (the propellant is burnt): the descent flown in 6 DOF,
    and as a point mass."""
    p, traj, s, _ = calm_flight
    t, alt, vz = traj.t, -traj.body.r_n.z, traj.body.v_n.z
    drogue, main = p.rocket.parachutes
    main_trigger = s["main_deploy_time_s"] - float(main.delay_s)
    if canopy == "drogue":
        # 15 s (5 time constants v_t/g) after full opening, until the main is triggered at 350 m
        window = (t > s["drogue_deploy_time_s"] + float(drogue.opening_time_s) + 15.0) & (t < main_trigger)
        cd_s = float(drogue.cd_s_m2)
    else:
        # the drogue stays attached: both drag areas act
        window = (t > s["main_deploy_time_s"] + float(main.opening_time_s) + 5.0) & (t < s["impact_time_s"])
        cd_s = float(drogue.cd_s_m2 + main.cd_s_m2)
    assert np.ptp(t[window]) > 20.0  # a long stretch of descent is tested [s]
    m = float(mass_properties(p, t[window][0]).mass)
    assert m == pytest.approx(float(p.rocket.dry_mass_kg), abs=1e-15)  # burnt out: dry mass
    rho = np.asarray(isa(float(p.environment.site_altitude_m) + alt[window]).density)
    v_terminal = np.sqrt(2 * m * G0 / (rho * cd_s))
    # 2 %: the acceptance bound of the brief. The deviation is the quasi-steady lag of a terminal
    # speed that shrinks as the air thickens (measured 0.18 % under the drogue, 0.009 % under the
    # main); the next assertion accounts for it exactly.
    np.testing.assert_allclose(vz[window], v_terminal, rtol=0.02)
    # Force balance with the actual deceleration: m dv/dt = m g − ½ ρ Cd·S v², i.e.
    # v = v_t sqrt(1 − a/g), with a from central differences of the trajectory. Measured residual
    # 3e-6 (drogue: a 0.06 m/s horizontal remainder of the apogee speed; O(h²) differences) and
    # 4e-10 (main): 1e-4.
    accel = np.gradient(vz, t)[window]
    np.testing.assert_allclose(vz[window], v_terminal * np.sqrt(1 - accel / G0), rtol=1e-4)
    # The same flight with the point-mass descent (up to 5 s periods, where central differences are no measure of
    # a) sinks as fast at the same heights. Measured: 5e-9 under the main; under the drogue 2e-6, but 9.9e-5 (2.6 mm/s)
    # where its ~3 s RK4 steps hand over to the 0.25 s 6-DOF ones around the 450 m layer boundary (the long steps'
    # own error, 3 cm of height over the handover): 2e-4.
    _, traj_m, _, _ = point_mass_calm_flight
    t_m, alt_m = traj_m.t, -traj_m.body.r_n.z
    late = (alt_m > alt[window].min()) & (alt_m < alt[window].max()) & (t_m > t[window].min() + 20.0)
    assert np.count_nonzero(late) > 5
    order = np.argsort(alt[window])
    sink = np.interp(alt_m[late], alt[window][order], vz[window][order])
    np.testing.assert_allclose(traj_m.body.v_n.z[late], sink, rtol=2e-4)


def test_drifts_with_the_wind_under_the_main(windy_flight):
    """Under a canopy the horizontal air-relative velocity relaxes with time constant v_t/g
    (≈ 0.6 s under the main): below the 275 m layer boundary the rocket drifts at the wind of
    layer 0, 7.5 m/s toward the north (it blows from 180°)."""
    p, traj, s, _ = windy_flight
    t, alt, v = traj.t, -traj.body.r_n.z, traj.body.v_n
    # 150 m below the boundary at ~5.8 m/s: 26 s, ~40 time constants after the wind jump
    window = (alt < 125.0) & (t > s["main_deploy_time_s"]) & (t < s["impact_time_s"])
    assert np.ptp(t[window]) > 20.0  # [s]
    wind = p.environment.wind
    # exp(−40)·7.5 m/s is nothing; what remains is the decaying swing of the body under its canopies
    # (measured 1e-9 m/s): 1e-6 m/s.
    np.testing.assert_allclose(v.x[window], float(wind.north_mps[0]), atol=1e-6)
    np.testing.assert_allclose(v.y[window], float(wind.east_mps[0]), atol=1e-6)
    assert float(wind.north_mps[0]) == pytest.approx(7.5, rel=1e-15)


def test_point_mass_descent(windy_flight, settings):
    """Once the swing has died out under a canopy the body flies as a point mass: its rates zero, its attitude held,
    in periods up to ``POINT_MASS_MAX_S`` with RK4 steps h·λ ≤ ``POINT_MASS_H_RATE`` (λ the drag's settling rate),
    none within ``swing_settle_s`` of the main's settling nor across a wind-layer boundary or the main's trigger
    altitude; with ``point_mass_descent`` off every period is a 6-DOF one of at most ``descent_dt_s``."""
    p, traj, s, _ = windy_flight
    t = np.concatenate([[0.0], traj.t])
    periods = np.diff(t)
    long = np.nonzero(periods > settings.descent_dt_s * (1 + 1e-9))[0]  # period k runs from state k - 1 to k
    assert len(long) > 20
    assert periods.max() <= POINT_MASS_MAX_S
    omega = np.asarray(traj.body.omega_b.to_array())
    q = np.asarray(traj.body.q_nb.to_array())
    np.testing.assert_array_equal(omega[long], 0.0)
    np.testing.assert_allclose(q[long], q[long - 1], rtol=0, atol=1e-15)  # renormalised each step: rounding only
    # the step bound, from the period start's state (no turbulence: the air moves with the mean wind)
    altitude, v = -np.asarray(traj.body.r_n.z), np.asarray(traj.body.v_n.to_array())
    wind = np.asarray(jax.vmap(lambda h: p.environment.wind.velocity_n(h).to_array())(jnp.asarray(altitude)))
    kappa = np.asarray(traj.canopy.drag_per_m)
    g = np.asarray(p.environment.gravity_mps2(float(p.environment.site_altitude_m) + altitude))
    rate = 2.0 * np.maximum(kappa * np.linalg.norm(v - wind, axis=-1), np.sqrt(g * kappa))
    assert np.all(periods[long] * rate[long - 1] <= POINT_MASS_H_RATE * (1 + 1e-9))
    main = p.rocket.parachutes[1]
    settled = s["main_deploy_time_s"] + float(main.opening_time_s) + settings.settle_s
    starts = t[:-1]
    assert not np.any((starts[long] >= settled - 1e-9) & (starts[long] < settled + settings.swing_settle_s))
    for level in [*np.asarray(p.environment.wind.bottom_m)[1:], float(main.trigger_altitude_agl_m)]:
        above = np.concatenate([[True], altitude > level])
        assert np.all(above[long] == above[long + 1]), level  # no point-mass period crosses it
    off = jax.jit(lambda p: fly(p, dataclasses.replace(settings, point_mass_descent=False), N_PERIODS))(p)[1]
    assert np.diff(np.asarray(off.t)).max() <= settings.descent_dt_s * (1 + 1e-9)


# ------------------------------------------------------------------------------------- events


def test_summaries_of_both_drivers_agree(windy_flight, simulate_fn):
    """simulate_one (while loop over blocks) and fly (one scan) step the same flight."""
    p, _, s_fly, status_fly = windy_flight
    summary, status = simulate_fn(p)
    assert int(status) == status_fly == Status.OK
    for name, value in floats(summary).items():
        # Two compiled programs of the same steps. Measured bit-identical; XLA could fuse the two
        # loops differently (last-ulp differences amplified over ~2000 steps, cf. the vmap test),
        # so 1e-12 relative rather than equality.
        assert value == pytest.approx(s_fly[name], rel=1e-12, abs=1e-12), name


def test_rail_exit_and_burnout(windy_flight):
    p, traj, s, _ = windy_flight
    t, speed = traj.t, np.linalg.norm(traj.body.v_n.to_array(), axis=-1)
    assert float(p.rocket.motor.ignition_time_s) < s["rail_exit_time_s"] < s["burnout_time_s"]
    assert s["burnout_time_s"] == pytest.approx(float(p.rocket.motor.ignition_time_s + p.rocket.motor.burn_time_s), abs=1e-12)
    j = bracket(t, s["rail_exit_time_s"])
    assert speed[j] <= s["rail_exit_speed_mps"] <= speed[j + 1]  # accelerating: between the samples
    # on the rail the body moves along it only and does not rotate
    on_rail = t < t[j]
    along = traj.body.v_n.to_array()[on_rail] @ np.asarray(p.launch.rail_direction_n.to_array())
    np.testing.assert_allclose(along, speed[on_rail], rtol=1e-12)
    np.testing.assert_array_equal(traj.body.omega_b.to_array()[on_rail], 0.0)
    assert 15.0 < s["rail_exit_speed_mps"] < 25.0  # a sane 4 m rail for this thrust-to-weight ratio
    j = bracket(t, s["burnout_time_s"])
    alt = -traj.body.r_n.z
    assert alt[j] <= s["burnout_altitude_agl_m"] <= alt[j + 1]


def test_apogee_is_the_top_of_the_trajectory(windy_flight, period_s):
    _, traj, s, _ = windy_flight
    t, alt, climb = traj.t, -traj.body.r_n.z, -traj.body.v_n.z
    j = bracket(t, s["apogee_time_s"])
    assert climb[j] > 0.0 >= climb[j + 1]  # the vertical velocity changes sign in that period
    assert t[j + 1] - t[j] == pytest.approx(period_s, abs=1e-12)
    # The sampled maximum is at most ½·a·(h/2)² below the true one, with a ≈ g + drag ≈ 11 m/s²:
    # 2.2e-3 m at h = 40 ms; the Hermite interpolant's own error (h⁴·alt⁗/384) is negligible.
    assert alt.max() - 1e-9 <= s["apogee_agl_m"] <= alt.max() + 0.5 * 11.0 * (period_s / 2) ** 2
    assert int(np.argmax(alt)) in (j, j + 1)
    # |v_z| at the samples around apogee is at most one period of deceleration: ≤ 11 m/s² · h
    assert max(abs(climb[j]), abs(climb[j + 1])) <= 11.0 * period_s
    for coord, value in ((traj.body.r_n.x, s["apogee_north_m"]), (traj.body.r_n.y, s["apogee_east_m"])):
        assert min(coord[j], coord[j + 1]) <= value <= max(coord[j], coord[j + 1])


def test_parachute_triggers(windy_flight):
    p, traj, s, _ = windy_flight
    t, alt = traj.t, -traj.body.r_n.z
    drogue, main = p.rocket.parachutes
    assert (drogue.name, main.name) == ("drogue", "main")
    # drogue: triggered at apogee (no altitude given), opens 0.5 s later
    assert float(drogue.delay_s) == 0.5 and not np.isfinite(float(drogue.trigger_altitude_agl_m))
    assert s["drogue_deploy_time_s"] == pytest.approx(s["apogee_time_s"] + 0.5, abs=1e-12)
    # main: triggered when the altitude crosses 350 m on the way down, opens 1 s later
    assert float(main.trigger_altitude_agl_m) == 350.0 and float(main.delay_s) == 1.0
    trigger = s["main_deploy_time_s"] - 1.0
    j = bracket(t, trigger)
    assert alt[j] > 350.0 >= alt[j + 1]
    assert t[j] > s["apogee_time_s"]  # on the way down, not the way up through 350 m
    # the crossing time is the linear interpolation of the sampled altitudes (the documented rule)
    frac = (alt[j] - 350.0) / (alt[j] - alt[j + 1])
    assert trigger == pytest.approx(t[j] + frac * (t[j + 1] - t[j]), abs=1e-9)
    # the main really opens then: the descent rate drops from the drogue's to the main's value
    k_before = bracket(t, s["main_deploy_time_s"])
    k_after = bracket(t, s["main_deploy_time_s"] + float(main.opening_time_s) + 3.0)
    assert traj.body.v_n.z[k_before] > 20.0 and traj.body.v_n.z[k_after + 1] < 8.0


def test_impact_and_frozen_after_landing(windy_flight):
    _, traj, s, status = windy_flight
    assert status == Status.OK
    t, alt = traj.t, -traj.body.r_n.z
    j = bracket(t, s["impact_time_s"])
    assert alt[j] > 0.0 >= alt[j + 1]
    speed = np.linalg.norm(traj.body.v_n.to_array(), axis=-1)
    assert min(speed[j], speed[j + 1]) - 1e-12 <= s["impact_speed_mps"] <= max(speed[j], speed[j + 1]) + 1e-12
    # After the landing period nothing changes any more (the state is frozen, not re-integrated).
    landed = np.arange(len(t)) >= j + 1
    assert landed.sum() > 100
    for leaf in jax.tree_util.tree_leaves(traj.body) + jax.tree_util.tree_leaves(traj.events):
        leaf = np.asarray(leaf)
        np.testing.assert_array_equal(leaf[landed], np.broadcast_to(leaf[j + 1], leaf[landed].shape))
    assert np.all(np.diff(t[landed]) > 0)  # the clock itself keeps running


def test_attitude_stays_unit_and_state_finite(windy_flight):
    _, traj, _, _ = windy_flight
    q = traj.body.q_nb.to_array()
    np.testing.assert_allclose(np.linalg.norm(q, axis=-1), 1.0, atol=1e-14)  # renormalised every step
    assert all(np.all(np.isfinite(np.asarray(x))) for x in jax.tree_util.tree_leaves(traj.body))
    assert not np.any(np.asarray(traj.events.non_finite))


def test_tick_counts_control_periods(windy_flight, period_s):
    """The tick is +1 per period, also in steady descent (longer periods), in the periods that end at an event
    (shorter: ``event_period``) and after landing; until the first longer period every period is the regular one
    (``open_loop_dt_s``) but those, and the clock is their float sum."""
    _, traj, _, _ = windy_flight
    assert traj.tick.dtype == np.int32
    np.testing.assert_array_equal(traj.tick, np.arange(1, N_PERIODS + 1))
    periods = np.diff(traj.t, prepend=0.0)
    first_long = int(np.argmax(periods > period_s * (1 + 1e-9)))
    assert first_long > 100  # after the climb, under canopy
    regular = np.isclose(periods[:first_long], period_s, rtol=1e-9, atol=0)
    assert 5 < np.count_nonzero(~regular) < 30  # the rail exit, two wind-layer boundaries up, thrust-curve points
    assert np.all(periods[:first_long][~regular] < period_s)
    assert traj.t[-1] > N_PERIODS * period_s  # the descent periods are longer


def test_periods_end_at_the_events(windy_flight, period_s):
    """Without a controller and sensors, a period ends at each thrust-curve point (exactly), and just past the
    rail exit and each wind-layer boundary crossing (predicted at the period start's velocity, overshot by
    ``EVENT_OVERSHOOT`` of the period)."""
    p, traj, s, _ = windy_flight
    t = np.concatenate([[0.0], traj.t])
    dt = period_s
    points = float(p.rocket.motor.ignition_time_s) + np.asarray(p.rocket.motor.time_s)
    np.testing.assert_allclose(t[np.abs(t[:, None] - points).argmin(axis=0)], points, rtol=0, atol=1e-12)
    # the rail exit: accelerating at ~66 m/s² from ≥ 15 m/s, the exit comes ≤ a·τ²/(2v) (3.5 ms at τ = 40 ms) before the
    # end of a period predicted at the start's speed
    j = bracket(t, s["rail_exit_time_s"])
    assert 0.0 < t[j + 1] - s["rail_exit_time_s"] <= EVENT_OVERSHOOT * dt + 66.0 * dt**2 / (2 * 15.0)
    altitude = np.concatenate([[0.0], -traj.body.r_n.z])
    apogee = int(np.argmax(altitude))
    for boundary in np.asarray(p.environment.wind.bottom_m)[1:]:
        j = int(np.argmax(altitude[:apogee] > boundary)) - 1  # the period in which the climb crosses it
        crossing = t[j] + (t[j + 1] - t[j]) * (boundary - altitude[j]) / (altitude[j + 1] - altitude[j])
        # climbing at ≥ 100 m/s against ≤ 30 m/s² of deceleration: the overshoot plus ≤ a·τ²/(2v) (2.4e-4 s at 40 ms;
        # measured 4.03e-4 s in all, the overshoot 4e-4 s of it)
        assert 0.0 < t[j + 1] - crossing <= EVENT_OVERSHOOT * dt + 30.0 * dt**2 / (2 * 100.0)


def test_every_output_has_a_metric(windy_flight):
    """Each output of flight_summary and the status has a unit and a meaning; the parachutes' deploy
    times are made from their names; the units agree with the names' suffixes."""
    p, _, s, _ = windy_flight
    assert set(s) == set(METRICS) - {"status"} | {f"{c.name}_deploy_time_s" for c in p.rocket.parachutes}
    suffix_units = {"_mps": "m/s", "_pa": "Pa", "_m": "m", "_s": "s"}
    for name in [*s, "status"]:
        unit, meaning = metric(name)
        assert unit and meaning, name
        assert unit == next((u for x, u in suffix_units.items() if name.endswith(x)), "1"), name
    assert "drogue" in metric("drogue_deploy_time_s").meaning
    with pytest.raises(KeyError):
        metric("apogee_agl_ft")


# --------------------------------------------------------------------------- batch and status


GUSTY_REALIZATIONS = (41, 42, 51)
"""lynx_nominal realizations whose gusts once made point-mass periods unstable (a gust that leaves the canopy nearly
still in the air, then the fall back to its terminal speed) or reach below the ground: status 1 (non-finite)."""


def test_vmap_equals_a_loop_of_single_flights(lynx_campaign, settings, simulate_fn):
    """Dispersed realizations under jax.vmap (as the runner flies them) against the same draws
    flown one at a time by the jitted single-flight function; all land (``GUSTY_REALIZATIONS``)."""
    key = jax.random.key(lynx_campaign.config.seed)
    indices = jnp.asarray(GUSTY_REALIZATIONS, dtype=jnp.uint32)
    batch_summary, batch_status, batch_drawn = jax.jit(
        jax.vmap(lambda i: realization(lynx_campaign, settings, key, i))
    )(indices)
    draw = jax.jit(lambda i: sample_dispersions(lynx_campaign, realization_key(key, i)))
    for i, index in enumerate(GUSTY_REALIZATIONS):
        drawn = draw(jnp.uint32(index))
        params = flight_params(lynx_campaign, {**lynx_campaign.nominal, **drawn}, realization_key(key, index))
        for name, value in drawn.items():
            assert float(value) == float(batch_drawn[name][i]), name  # integer PRNG: bit-identical
        summary, status = simulate_fn(params)
        assert int(status) == int(batch_status[i]) == Status.OK
        for name, value in floats(summary).items():
            # Not bit-identical: the batched program is vectorised and fused differently from the
            # scalar one (and the nominal values are constants in one, arguments in the other), so
            # last-ulp differences appear, which ~2000 steps (mostly the swinging canopies) amplify
            # to 1.8e-13 relative at most (measured, realizations 0-2): 1e-12 relative, as the
            # brief asks, and 1e-9 absolute for values near zero.
            assert value == pytest.approx(float(batch_summary[name][i]), rel=1e-12, abs=1e-9), (i, name)
    # the realizations really differ (the comparison is not between identical flights)
    assert len(set(np.round(np.asarray(batch_summary["impact_north_m"]), 6))) == len(GUSTY_REALIZATIONS)


def test_max_time_status(lynx_params):
    """A flight not on the ground at max_time_s stops there with Status.MAX_TIME."""
    settings = SimSettings(max_time_s=5.0, block_steps=50)  # 1 s blocks: stops at t = 5 s
    summary, status = jax.jit(lambda p: simulate_one(p, settings))(lynx_params)
    s = floats(summary)
    assert int(status) == Status.MAX_TIME
    assert np.isnan(s["impact_time_s"]) and np.isnan(s["impact_north_m"])  # did not land
    assert np.isnan(s["apogee_time_s"]) and np.isnan(s["drogue_deploy_time_s"])  # still climbing at 5 s
    t_bo = float(lynx_params.rocket.motor.ignition_time_s + lynx_params.rocket.motor.burn_time_s)
    assert s["burnout_time_s"] == pytest.approx(t_bo, abs=1e-12)  # what did happen is recorded
    assert np.isfinite(s["rail_exit_time_s"])
    assert Status(int(status)).message.startswith("not on the ground")


def test_outside_atmosphere_status(lynx_params):
    """An apogee above the standard atmosphere's 47 km top is Status.OUTSIDE_ATMOSPHERE."""
    state = initial_state(lynx_params)
    landed = dataclasses.replace(
        state.events, apogee_time=jnp.asarray(20.0), apogee_altitude=jnp.asarray(1500.0), impact_time=jnp.asarray(90.0)
    )
    state = dataclasses.replace(state, events=landed)
    assert int(flight_summary(lynx_params, state)[1]) == Status.OK
    env = dataclasses.replace(lynx_params.environment, site_altitude_m=jnp.asarray(46_000.0))  # 47.5 km at apogee
    high = dataclasses.replace(lynx_params, environment=env)
    assert int(flight_summary(high, state)[1]) == Status.OUTSIDE_ATMOSPHERE


def test_turbulence_changes_the_flight_and_is_reproducible(fly_fn, lynx_params, windy_flight):
    """The nominal flight has light turbulence: it lands elsewhere than in the mean wind alone; the same
    key gives the same flight to the bit; another key, another flight."""
    env = lynx_params.environment
    rekeyed = dataclasses.replace(env.turbulence, key=jax.random.fold_in(env.turbulence.key, 1))
    turbulent, again, other = (
        _fly(fly_fn, dataclasses.replace(lynx_params, environment=dataclasses.replace(env, turbulence=t)))[2]
        for t in (env.turbulence, env.turbulence, rekeyed)
    )
    assert again == turbulent
    for summary in (windy_flight[2], other):
        shift = np.hypot(summary["impact_north_m"] - turbulent["impact_north_m"], summary["impact_east_m"] - turbulent["impact_east_m"])
        assert shift > 1.0  # light gusts move the landing point by metres to hundreds of metres


def test_airbrakes_add_their_axial_force(lynx_params):
    """The ΔCA schedule (time since ignition) adds ΔCA·q̄·S along −x: the body-x acceleration
    changes by exactly that over the mass, at a time in the middle of a ramp."""
    p = still(lynx_params)
    ev = dataclasses.replace(initial_state(p).events, rail_exit_time=jnp.asarray(0.8))
    body = RigidBodyState(Vec3(0.0, 0.0, -900.0), Vec3(5.0, 0.0, -150.0), p.launch.q_nb0, Vec3(0.0, 0.0, 0.0))
    braked = dataclasses.replace(p, rocket=dataclasses.replace(
        p.rocket, airbrake_time_s=jnp.array([0.0, 4.0, 6.0]), airbrake_delta_ca=jnp.array([0.0, 0.0, 0.6])))  # fmt: skip
    t = jnp.asarray(5.5)  # 5.0 s after ignition: halfway up the ramp, ΔCA = 0.3
    neutral = jnp.zeros(p.rocket.aero.n_canards)
    (d0, diag), (d1, _) = (derivatives(t, body, q, neutral, Vec3.zeros(), ev) for q in (p, braked))
    delta_b = p.launch.q_nb0.rotate_inverse(d1.v_n - d0.v_n)
    mass = float(mass_properties(p, 5.5).mass)
    expected = -0.3 * float(diag.qbar) * float(p.rocket.aero.reference_area_m2) / mass
    assert float(delta_b.x) == pytest.approx(expected, rel=1e-12)  # the same state: only ΔCA differs
    assert abs(float(delta_b.y)) < 1e-12 and abs(float(delta_b.z)) < 1e-12

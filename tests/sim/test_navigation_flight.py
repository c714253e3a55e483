"""The navigation filters in flight (``gnc.navigation = "filters"``): the thesis's Fig. 7 case (the Lynx under a
constant 10 m/s headwind, controller on from 1 s, nominal, no turbulence) on the thesis's sensors, on sensors
without errors, initialised from the rail and from pad samples; a filter that fails.

What could break and is checked: the filters' frames and signs (the estimates must follow the truth: with errors
off they can only differ by the filters' own discretisation), the controller fed by them (it must still pull the
flight path onto the reference), TRIAD on the pad, the per-flight outputs against the recorded trajectory, and a
failed covariance as a status code.
"""

from __future__ import annotations

import dataclasses
import functools
import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from rocketmc.campaign import campaign_from_dict, read_campaign_tables
from rocketmc.campaign.model import nominal_params
from rocketmc.campaign.runner import realization_params, sim_settings
from rocketmc.gnc.attitude_filter import attitude_error_b
from rocketmc.gnc.guidance import reference_direction
from rocketmc.sensors.avionics import gyroscope_bias_b
from rocketmc.sim.events import rail_start_n
from rocketmc.sim.flight import fly, initial_state
from rocketmc.sim.outputs import flight_summary
from rocketmc.sim.state import Status

from ..conftest import CAMPAIGNS

pytestmark = pytest.mark.slow  # campaigns or long flights: left out by make test-fast

N_PERIODS = 1000  # 20 s at 0.02 s: past the window (10 s after liftoff), burnout (~4 s) and apogee (~19 s)
ATTITUDE_DEG, VELOCITY_MPS = 6.0, 2.0
"""Bounds on the thesis filters' errors through the ascent, measured 4.05° (near apogee: the roll about the field
line is unobservable, docs/gnc.md §2) and 1.10 m/s; what a frame or sign slip breaks by far."""
TRUTH_ONLY = {"attitude_deg": 1.5, "position_m": 3.0, "velocity_mps": 1.2}
"""Bounds on the errors without sensor errors through the ascent, measured 0.91°, 2.05 m, 0.78 m/s: the
accelerometer's sample held over the period lags the acceleration's jump at liftoff by one period (a·T ≈ 0.7 m/s,
integrated until the GNSS), and the gyro's held rates shift the attitude, which the magnetometer pulls back but
for its roll about the field line."""


def headwind(errors: bool = True, pad_samples: int | None = None, magnetometer: dict | None = None,
             sensors: dict | None = None, initialisation: str = "pad"):
    """lynx_ballistic_gnc_1s under a constant 10 m/s wind from the launch azimuth, nothing dispersed; errors False:
    every sensor truth-only; pad_samples: the filters initialised from that many pad ticks (``initialisation``),
    the motor lit 0.2 s after them;
    magnetometer: fields of its [avionics.magnetometer] table; sensors: [avionics] tables of fields over the thesis
    part's."""
    path = CAMPAIGNS / "lynx_ballistic_gnc_1s.toml"
    raw = read_campaign_tables(path)
    raw["environment"] = {"wind": {"model": "constant", "speed_mps": 10.0, "from_deg": raw["launch"]["azimuth_deg"]},
                          "magnetic_field": raw["environment"]["magnetic_field"]}  # the thesis's dipole, as flown
    raw["dispersions"] = {}
    if not errors:
        raw["avionics"].update({sensor: {"truth_only": True} for sensor in
                                ("accelerometer", "gyroscope", "magnetometer", "barometer", "gnss")})  # fmt: skip
    if magnetometer is not None:
        raw["avionics"]["magnetometer"] = magnetometer
    raw["avionics"].update(sensors or {})
    if pad_samples is not None:
        raw["gnc"]["filters"] = {"initialisation": initialisation, "pad_samples": pad_samples}
        raw["rocket"].setdefault("motor", {})["ignition_delay_s"] = pad_samples * 0.02 + 0.2
    return campaign_from_dict(raw, path.parent)


@functools.cache
def compiled(settings):
    """``fly`` for N_PERIODS, jitted once per settings (and so once per pytree structure of the parameters)."""
    return jax.jit(lambda p: (lambda final, traj: (traj, flight_summary(p, final)))(*fly(p, settings, N_PERIODS)))


def flown(campaign, params=None):
    """(parameters, trajectory, (summary, status)) of the campaign's nominal flight or of ``params``."""
    params = nominal_params(campaign) if params is None else params
    return params, *compiled(sim_settings(campaign))(params)


@pytest.fixture(scope="module")
def thesis():
    return flown(headwind())


def estimates(traj):
    """(times [s], the filters' state, the true body) at the same instants: the state recorded after period k holds
    the filters' solution at its start t_k, the body recorded after period k − 1 is the truth then."""
    shift = lambda tree, part: jax.tree_util.tree_map(lambda x: x[part], tree)  # noqa: E731
    return np.asarray(traj.t[:-1]), shift(traj.gnc.navigation, slice(1, None)), shift(traj.body, slice(None, -1))


def attitude_errors_deg(traj) -> tuple[np.ndarray, np.ndarray]:
    """(times [s], |δϑ| [deg] of the filters' attitude against the truth then)."""
    t, filters, body = estimates(traj)
    return t, np.degrees(np.asarray(attitude_error_b(filters.attitude.q_nb, body.q_nb).norm()))


def position_velocity_errors(traj) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(times [s], |r̂ − r| [m], |v̂ − v| [m/s]) at the same instants."""
    t, filters, body = estimates(traj)
    return t, np.asarray((filters.position.r_n - body.r_n).norm()), np.asarray((filters.position.v_n - body.v_n).norm())


def test_thesis_filters_follow_the_truth_and_steer(thesis):
    """The thesis's sensors and tuning: through the ascent the attitude estimate stays within ATTITUDE_DEG of the
    truth and the velocity estimate within VELOCITY_MPS (integrated open loop from the accelerometer until the GNSS
    at 10.5 s); the controller on those estimates pulls the flight path within 3° of the reference in the window's
    last 5 s (1.5° on perfect navigation, tests/sim/test_closed_loop.py)."""
    p, traj, (summary, status) = thesis
    assert int(status) == Status.MAX_TIME  # flown 20 s, not to the ground: nothing else failed
    liftoff = float(traj.gnc.liftoff_time[-1])
    t, attitude = attitude_errors_deg(traj)
    _, _, velocity = position_velocity_errors(traj)
    ascent = (t >= liftoff) & (t < float(summary["apogee_time_s"]))
    assert attitude[ascent].max() < ATTITUDE_DEG
    assert velocity[ascent].max() < VELOCITY_MPS
    t = np.asarray(traj.t)
    v = traj.body.v_n
    gamma = np.degrees(np.arctan2(-np.asarray(v.z), np.hypot(np.asarray(v.x), np.asarray(v.y))))
    d = reference_direction(p.gnc.guidance, None, t - liftoff)
    settled = (t - liftoff >= 5.0) & (t - liftoff < 10.0)
    assert np.abs(gamma - np.degrees(np.arcsin(-np.asarray(d.z))))[settled].max() < 3.0


def test_outputs_agree_with_the_trajectory(thesis):
    """The per-flight outputs against the same quantities taken from the recorded trajectory: the window's and
    the ascent's largest attitude error, and the errors at the first tick after burnout."""
    p, traj, (summary, _) = thesis
    t, attitude = attitude_errors_deg(traj)
    _, position, velocity = position_velocity_errors(traj)
    liftoff = float(traj.gnc.liftoff_time[-1])
    assert math.isclose(float(summary["control_active_time_s"]), 9.0, abs_tol=0.02 + 1e-9)
    window = (t - liftoff >= 1.0) & (t - liftoff < 10.0)  # as the controller tests it, on the same sums of periods
    assert math.degrees(float(summary["attitude_error_max_window_rad"])) == pytest.approx(attitude[window].max(), rel=1e-9)
    first_motion = np.flatnonzero(np.asarray(traj.body.v_n.norm()) > 0.0)[0]  # recorded after the period: t_k+1
    ascent = (np.arange(len(t)) >= first_motion) & (t < float(summary["apogee_time_s"]))
    assert math.degrees(float(summary["attitude_error_max_ascent_rad"])) == pytest.approx(attitude[ascent].max(), rel=1e-9)
    rms = math.sqrt(np.mean(np.radians(attitude[window]) ** 2))
    assert float(summary["attitude_error_rms_window_rad"]) == pytest.approx(rms, rel=1e-9)
    after = np.searchsorted(t, float(summary["burnout_time_s"]))  # the first tick at or after burnout
    assert float(summary["position_error_burnout_m"]) == pytest.approx(position[after], rel=1e-9)
    assert float(summary["velocity_error_burnout_mps"]) == pytest.approx(velocity[after], rel=1e-9)
    for name in ("attitude_nees_window", "position_nees_window", "gyro_bias_error_window_end_rad_s",
                 "position_error_apogee_m", "velocity_error_apogee_mps"):  # fmt: skip
        assert np.isfinite(float(summary[name])) and float(summary[name]) > 0.0, name


def test_without_sensor_errors_the_estimates_are_the_truth_to_discretisation():
    """Every sensor truth-only: what is left is the filters' own discretisation (the accelerometer's and gyro's
    samples held over each 20 ms period) and the magnetometer's pull toward the exact field direction
    (``TRUTH_ONLY``)."""
    _, traj, (summary, status) = flown(headwind(errors=False))
    assert int(status) == Status.MAX_TIME
    t, attitude = attitude_errors_deg(traj)
    _, position, velocity = position_velocity_errors(traj)
    ascent = t < float(summary["apogee_time_s"])
    assert attitude[ascent].max() < TRUTH_ONLY["attitude_deg"]
    assert position[ascent].max() < TRUTH_ONLY["position_m"]
    assert velocity[ascent].max() < TRUTH_ONLY["velocity_mps"]


PAD_TICKS = 250
"""Pad samples of the TRIAD test: 5 s at 50 Hz, the thesis gyro's 0.3 deg/s noise averaged to 0.019 deg/s."""


@pytest.mark.parametrize("initialisation", ["pad", "level"])
def test_pad_samples_initialise_the_attitude_and_the_gyro_bias(initialisation):
    """PAD_TICKS pad ticks, the motor lit 0.2 s later: at the last of them the attitude is set with the initial
    covariance, by TRIAD on the mean accelerometer and magnetometer directions ("pad") or as the rail's, held
    until then, levelled by the mean accelerometer direction ("level"), and the gyroscope's mean rate sets its bias.
    The thesis's sensors' accelerometer bias (≤ 0.04 m/s² against g: 0.2°), the averaged noise and the
    magnetometer's 0.3° misalignment bound the attitude's error to ~0.5°; 1.5° leaves room, and a frame or
    sign slip is tens of degrees off. The gyroscope's bias walk off (the mean then estimates a constant),
    each axis of the bias estimate is within 4 σ/√n of the drawn bias (σ the gyro's 0.3 deg/s per sample, n the
    PAD_TICKS samples at rest; 4 σ: a chance of 6e-5 per axis to fail by noise; its 0.015 deg/s LSB is dithered by
    that noise); the rail's initialisation has a zero bias, 0.1 to 0.25 deg/s off."""
    campaign = headwind(pad_samples=PAD_TICKS, sensors={"gyroscope": {"bias_walk": 0.0}}, initialisation=initialisation)
    p, traj, (_, status) = flown(campaign)
    assert int(status) == Status.MAX_TIME  # flown 20 s, not to the ground: nothing else failed
    variance = np.asarray(traj.gnc.navigation.attitude.cov[:, 0, 0])
    reset = np.flatnonzero(variance == float(p.gnc.filters.attitude.initial_attitude_std) ** 2)
    if initialisation == "level":  # the rail's attitude and covariance held from t = 0 to the reset
        q_nb = np.asarray(traj.gnc.navigation.attitude.q_nb.to_array())
        np.testing.assert_array_equal(q_nb[: PAD_TICKS - 1], np.broadcast_to(p.gnc.rail_q_nb.to_array(), (PAD_TICKS - 1, 4)))
        reset = reset[reset >= PAD_TICKS - 1]
    assert len(reset) == 1 and reset[0] == PAD_TICKS - 1  # the period whose start is the last tick on the pad
    assert attitude_errors_deg(traj)[1][reset[0] - 1] < 1.5  # the solution at that tick against the truth then
    assert float(traj.gnc.liftoff_time[-1]) > PAD_TICKS * 0.02  # liftoff sensed after the pad samples
    at = lambda tree: jax.tree_util.tree_map(lambda x: x[reset[0]], tree)  # noqa: E731
    estimate = at(traj.gnc.navigation.attitude.bias_b).to_array()
    drawn = gyroscope_bias_b(p.avionics, at(traj.avionics)).to_array()
    tolerance = 4.0 * math.radians(campaign.config.avionics.gyroscope.noise_std) / math.sqrt(PAD_TICKS)
    assert np.all(np.abs(np.asarray(estimate - drawn)) < tolerance)
    assert np.abs(np.asarray(drawn)).max() > 2 * tolerance  # a zero estimate fails by far


def test_navigation_starts_from_the_nominal_rail_not_the_drawn_one():
    """A campaign dispersing the rail's elevation (σ 2°) and azimuth (σ 10°): a realization's rail is not the
    nominal, but its filters (and the raw sensors' dead reckoning) start from the nominal rail's attitude and the
    nominal rocket's CG on it, which is all the avionics know."""
    raw = read_campaign_tables(CAMPAIGNS / "lynx_ballistic_gnc_1s.toml")
    raw["dispersions"] = {"launch.elevation_deg": {"dist": "normal", "std": 2.0, "high": 89.0},
                          "launch.azimuth_deg": {"dist": "normal", "std": 10.0}}  # fmt: skip
    nominal = nominal_params(campaign_from_dict(raw, CAMPAIGNS))
    for navigation in ("filters", "sensors"):
        raw["gnc"]["navigation"] = navigation
        campaign = campaign_from_dict(raw, CAMPAIGNS)
        p, drawn = realization_params(campaign, jax.random.key(campaign.config.seed), 3)
        assert abs(float(drawn["launch.azimuth_deg"]) - 130.0) > 1.0  # this realization's rail is off the nominal
        gnc = initial_state(p).gnc.navigation
        q_nb, r_n = (gnc.attitude.q_nb, gnc.position.r_n) if navigation == "filters" else (gnc.q_nb, gnc.r_n)
        np.testing.assert_array_equal(np.asarray(q_nb.to_array()), np.asarray(nominal.launch.q_nb0.to_array()))
        assert float(attitude_error_b(q_nb, p.launch.q_nb0).norm()) > math.radians(1.0)
        if navigation == "filters":
            np.testing.assert_array_equal(np.asarray(r_n.to_array()), np.asarray(rail_start_n(nominal).to_array()))


def test_a_failed_filter_is_a_status_not_a_crash(thesis):
    """An infinite gyro-noise density makes the MEKF's covariance infinite at its first propagation: the filters
    hold their last good estimate and the flight ends with NAVIGATION_FAILED."""
    p = thesis[0]
    broken = dataclasses.replace(p.gnc.filters.attitude, gyro_noise=jnp.asarray(jnp.inf))
    p = dataclasses.replace(p, gnc=dataclasses.replace(p.gnc, filters=dataclasses.replace(p.gnc.filters, attitude=broken)))
    _, traj, (summary, status) = flown(headwind(), p)
    assert int(status) == Status.NAVIGATION_FAILED
    assert np.all(np.isfinite(np.asarray(traj.gnc.navigation.attitude.q_nb.w)))


def _with_feedback_bias(p, bias_deg: float):
    """``p`` with a bias of ``bias_deg`` on each fin's canard-feedback sensor."""
    feedback = p.avionics.canard_feedback
    feedback = dataclasses.replace(feedback, bias=feedback.bias + math.radians(bias_deg))
    return dataclasses.replace(p, avionics=dataclasses.replace(p.avionics, canard_feedback=feedback))


def test_the_controller_reads_the_canard_feedback_sensor(thesis):
    """The LQI's actuator states come from the canard-feedback sensor on the bus when it navigates from the sensors:
    a 1° bias on each fin's feedback changes the filters' flight (its canards, hence its path); on the true state
    ("truth") the controller reads the servos themselves, and the same bias changes no bit."""
    p, traj, (summary, _) = thesis
    _, biased, (biased_summary, _) = flown(headwind(), _with_feedback_bias(p, 1.0))
    rms = "canard_deflection_rms_rad"
    assert abs(float(biased_summary[rms]) / float(summary[rms]) - 1) > 1e-3
    assert np.abs(np.asarray(biased.body.r_n.z) - np.asarray(traj.body.r_n.z)).max() > 0.01  # [m]
    truth = headwind()
    truth = dataclasses.replace(truth, config=truth.config.model_copy(
        update={"gnc": truth.config.gnc.model_copy(update={"navigation": "truth"})}))  # fmt: skip
    p, traj, (summary, _) = flown(truth)
    _, biased, (biased_summary, _) = flown(truth, _with_feedback_bias(p, 1.0))
    for name, value in summary.items():
        np.testing.assert_array_equal(np.asarray(biased_summary[name]), np.asarray(value), err_msg=name)
    np.testing.assert_array_equal(np.asarray(biased.body.r_n.z), np.asarray(traj.body.r_n.z))


GNSS_OFFSET_M = 100.0
"""A constant GNSS position error, 100 m down, on the raw sensors' navigation (its height is the GNSS fix's)."""


def test_the_main_deploys_at_the_estimated_height():
    """lynx_nominal_ctrl_1s_sensors (raw-sensor navigation: its height the GNSS fix's), nothing dispersed, no wind,
    its GNSS exact but for a constant GNSS_OFFSET_M down (the slow sinusoid at 0 Hz, phase 90°): the navigation sees
    the rocket 100 m lower than it is, so the main (350 m above the pad) triggers at a true 450 m: the crossing of the
    true height plus the navigation's height error held from its last tick before the drogue (exactly −100 m, the
    fix at that tick), interpolated in the step as the true triggers are (to 1e-6 m: rounding); the drogue at the
    sensed apogee, after the true one. The recorded apogee is the true one."""
    path = CAMPAIGNS / "lynx_nominal_ctrl_1s_sensors.toml"
    raw = read_campaign_tables(path)
    raw["environment"] = {"wind": {"model": "constant", "speed_mps": 0.0, "from_deg": 0.0}}
    raw["dispersions"] = {}
    raw["avionics"]["gnss"] = {"position_noise_m": [0.0] * 3, "velocity_noise_mps": [0.0] * 3,
                               "sinusoid_frequency_hz": 0.0, "sinusoid_amplitude_m": [0.0, 0.0, GNSS_OFFSET_M],
                               "sinusoid_phase_deg": [0.0, 0.0, 90.0]}  # fmt: skip
    campaign = campaign_from_dict(raw, path.parent)
    p = nominal_params(campaign)
    main = [i for i, chute in enumerate(p.rocket.parachutes) if np.isfinite(float(chute.trigger_altitude_agl_m))][0]
    record = lambda s: (s.t, -s.body.r_n.z, s.events.chute_trigger_times, s.events.apogee_time)  # noqa: E731
    run = jax.jit(lambda p: fly(p, sim_settings(campaign), 5000, record=record)[1])  # past the main
    t, height, triggers, apogee = (np.asarray(x) if not isinstance(x, tuple) else tuple(map(np.asarray, x))
                                   for x in run(p))  # fmt: skip
    altitude = float(p.rocket.parachutes[main].trigger_altitude_agl_m)
    trigger = triggers[main][-1]
    assert np.isfinite(trigger)
    assert np.interp(trigger, t, height) == pytest.approx(altitude + GNSS_OFFSET_M, abs=1e-6)
    drogue = 1 - main
    assert np.isfinite(apogee[-1]) and triggers[drogue][-1] > apogee[-1]
    assert height[np.searchsorted(t, apogee[-1])] == pytest.approx(height.max(), abs=0.1)  # the true apogee


def test_thesis_sensors_navigation_has_not_diverged(thesis):
    """The thesis's filters on its sensors (largest window attitude error ~2°, velocity error ~1 m/s at burnout,
    NEES ~1e-4 and 0.2) are far inside every bound of ``navigation_diverged``."""
    summary = thesis[2][0]
    assert float(summary["navigation_diverged"]) == 0.0
    assert math.degrees(float(summary["attitude_error_max_window_rad"])) < 5.0  # half the 10° bound


def test_an_uncalibrated_magnetometer_is_flagged_as_diverged():
    """The BMX160's uncalibrated zero-B offset (±40 µT typical, data/sensors/bmx160_uncalibrated.toml) as a fixed
    hard-iron offset of that size on each axis: the MEKF follows a field direction tens of degrees off the true one
    (the Earth's field is ~47 µT here), the flight is flagged, and its status stays ok-or-not on its own merits."""
    campaign = headwind(magnetometer={"hard_iron": [40.0, -40.0, 40.0]})
    _, _, (summary, status) = flown(campaign)
    assert int(status) == Status.MAX_TIME  # flown 20 s, not to the ground: the flag is not a status
    assert math.degrees(float(summary["attitude_error_max_window_rad"])) > 10.0
    assert float(summary["navigation_diverged"]) == 1.0

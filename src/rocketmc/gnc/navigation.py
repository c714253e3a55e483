"""Navigation from the avionics bus (``NavigationMode``): ``SENSORS`` (``navigation = "sensors"``), raw sensors,
and ``FILTERS`` (``"filters"``), the MEKF (``attitude_filter``) and the position/velocity Kalman filter
(``position_filter``).

Raw sensors: body rates from the gyroscope, the launch attitude propagated by the gyroscope's rates (no
correction: its bias and noise integrate), position and velocity from the GNSS, held between fixes (zero
before the first fix), liftoff from the accelerometer (both modes).

Filters (docs/gnc.md §2-3), at each GNC tick t_k: position and velocity propagated from t_{k-1} with the accelerometer's
sample of t_{k-1} (the bus delivers it at t_k) rotated into NED by the attitude estimate of t_{k-1}, plus gravity;
the attitude propagated with the gyroscope's rates of t_{k-1} less the estimated bias; then the magnetometer's
update of the attitude, the GNSS's and the barometer's of position and velocity; the a-posteriori estimate is the
solution (the thesis fed the a-priori one forward, a tick late). Frames: NED from the pad, FRD body.
"""

from __future__ import annotations

import dataclasses
import enum
import math

import jax.numpy as jnp

from ..env.atmosphere import G0, pressure_height_m
from ..env.magnetic import first_order_field
from ..math import Quat, Vec3
from ..pytree import pytree_dataclass, static_field, tree_where
from ..sensors.avionics import Avionics, Bus, to_body
from .attitude_filter import (
    AttitudeEstimate, AttitudeTuning, attitude_error_b, attitude_nees, initial_attitude, magnetometer_nis, magnetometer_update,
    level, propagate_attitude, rotation_step, triad,
)  # fmt: skip
from .guidance import Navigation
from .position_filter import (
    PositionEstimate, PositionTuning, altitude_nis, altitude_update, gnss_nis, gnss_update, initial_position, position_nees,
    propagate_position,
)  # fmt: skip


class NavigationMode(enum.Enum):
    """What the controller reads (``gnc.control.navigate``); the value is the campaign's [gnc] ``navigation``:
    TRUTH, the true state; SENSORS, the raw sensors (``dead_reckoning``); FILTERS, the MEKF and the
    position/velocity Kalman filter on the bus (``filter_step``)."""

    TRUTH = "truth"
    SENSORS = "sensors"
    FILTERS = "filters"


LIFTOFF_SPECIFIC_FORCE_MPS2 = 2.0 * G0
"""Liftoff is sensed once the accelerometer reads more than this along the rocket's axis: at rest on the rail
it reads g·sin(elevation) ≤ g; a rocket leaves its rail at 5 g or more (the usual rule for a safe rail-exit
speed; Lynx ~6 g)."""


@pytree_dataclass
class DeadReckoning:
    """The raw-sensor navigation's state: t, the time of the last solution [s]; q_nb, the attitude then;
    omega_b, the body rates then [rad/s]; r_n, v_n, the last GNSS fix [m], [m/s] (NED from the pad)."""

    t: jnp.ndarray
    q_nb: Quat
    omega_b: Vec3
    r_n: Vec3
    v_n: Vec3


def initial_dead_reckoning(q_nb0: Quat) -> DeadReckoning:
    """On the pad at t = 0 with the launch attitude (from the rail's elevation and azimuth), at rest."""
    zero = jnp.zeros_like(q_nb0.w)
    still = Vec3(zero, zero, zero)
    return DeadReckoning(zero, q_nb0, still, still, still)


def dead_reckoning(av: Avionics, state: DeadReckoning, bus: Bus, t) -> tuple[Navigation, DeadReckoning]:
    """The raw-sensor solution at time t [s]: the attitude propagated from the last solution with its rates,
    then the bus's gyroscope rates and GNSS fix (the last ones held when none is fresh)."""
    q_nb = (state.q_nb * rotation_step(state.omega_b, t - state.t)).normalized()
    gyro, gnss = bus.gyroscope, bus.gnss
    omega_b = to_body(av.gyroscope.rotation, gyro.value)
    omega_b = Vec3(*(jnp.where(gyro.valid, w, 0.0) for w in omega_b))
    r_n = Vec3(*(jnp.where(gnss.fresh, gnss.value[i], held) for i, held in enumerate(state.r_n)))
    v_n = Vec3(*(jnp.where(gnss.fresh, gnss.value[3 + i], held) for i, held in enumerate(state.v_n)))
    return Navigation(r_n, v_n, q_nb, omega_b), DeadReckoning(t, q_nb, omega_b, r_n, v_n)


def liftoff_sensed(av: Avionics, bus: Bus):
    """True when the accelerometer reads more than ``LIFTOFF_SPECIFIC_FORCE_MPS2`` along the rocket's axis."""
    accel = bus.accelerometer
    return accel.valid & (to_body(av.accelerometer.rotation, accel.value).x > LIFTOFF_SPECIFIC_FORCE_MPS2)


# --- navigation = "filters": the MEKF and the position/velocity Kalman filter on the bus ----------------------


@pytree_dataclass
class FilterParams:
    """The navigation filters of one flight. attitude, position: their tunings; field_n (3,): the geomagnetic
    model's field at the pad [T, NED] and field_gradient (3, 3) its derivative along r_n [T/m] (the reference
    field direction at the estimated position, to first order: the dipole's second-order term over 10 km is
    ~3e-6 of the field); gnss_after_s: the position filter uses fixes from this simulation time [s]; level_fraction:
    how far the levelling turns the rail's tilt toward the accelerometer's [-] (``level``); pad_samples:
    the GNC ticks on the pad whose samples initialise the attitude and whose gyroscope's mean the bias (0: from the
    rail, zero bias; static); heading_from_field: the attitude by TRIAD from the accelerometer and magnetometer
    (False: the rail's, levelled by the accelerometer: ``level``; static); horizontal_only: GNSS updates of north and
    east only (static); barometer: the barometric height update (static); field_gate, gnss_gate, altitude_gate: the
    innovation gates of the magnetometer's, the GNSS's and the barometer's updates (``innovation_gate``; None: off;
    static)."""

    attitude: AttitudeTuning
    position: PositionTuning
    field_n: jnp.ndarray
    field_gradient: jnp.ndarray
    gnss_after_s: jnp.ndarray
    level_fraction: jnp.ndarray
    pad_samples: int = static_field()
    heading_from_field: bool = static_field()
    horizontal_only: bool = static_field()
    barometer: bool = static_field()
    field_gate: float | None = static_field()
    gnss_gate: float | None = static_field()
    altitude_gate: float | None = static_field()


@pytree_dataclass
class FilterState:
    """The filters' state: t, the time of the last solution [s]; attitude, position: the estimates then (a
    posteriori); omega_measured_b: the gyroscope's last rates [rad/s, body frame], with which the attitude is
    propagated over the next period; on the pad (before liftoff is sensed): the sums of the accelerometer's and
    magnetometer's samples [m/s², T, body frame] (their directions initialise TRIAD), of the gyroscope's [rad/s,
    body frame] and their count (their mean initialises the bias with TRIAD), of the barometer's [Pa] and their
    count (their mean is the pad pressure the barometric height is measured from), the GNC ticks on the pad;
    failed: a covariance was not finite or not positive (latched); errors: the estimation errors' totals
    (``NavigationErrors``); rejected (3,): the fresh magnetometer, GNSS and barometer samples their innovation gates
    rejected (counts)."""

    t: jnp.ndarray
    attitude: AttitudeEstimate
    position: PositionEstimate
    omega_measured_b: Vec3
    pad_force_b: Vec3
    pad_field_b: Vec3
    pad_rate_b: Vec3
    pad_rate_count: jnp.ndarray
    pad_pressure_sum: jnp.ndarray
    pad_pressure_count: jnp.ndarray
    pad_ticks: jnp.ndarray
    failed: jnp.ndarray
    errors: NavigationErrors
    rejected: jnp.ndarray


@pytree_dataclass
class NavigationErrors:
    """The filters' errors against the truth, summed or kept over the flight for its outputs
    (``navigation_summary``). window: the controller's active time [s] and, over it, ∫|δϑ|² dt [rad²·s], max |δϑ|
    [rad], ∫NEES dt of the attitude filter and of the position/velocity filter [s]; ascent: from liftoff to
    apogee, its time [s], ∫|δϑ|² dt and max |δϑ|; bias_error: |β − β̂| [rad/s] at the window's last tick;
    position and velocity errors [m], [m/s] at the first tick after burnout and after apogee (NaN before)."""

    window_time: jnp.ndarray
    window_attitude_sq: jnp.ndarray
    window_attitude_max: jnp.ndarray
    window_attitude_nees: jnp.ndarray
    window_position_nees: jnp.ndarray
    ascent_time: jnp.ndarray
    ascent_attitude_sq: jnp.ndarray
    ascent_attitude_max: jnp.ndarray
    bias_error: jnp.ndarray
    burnout_position: jnp.ndarray
    burnout_velocity: jnp.ndarray
    apogee_position: jnp.ndarray
    apogee_velocity: jnp.ndarray


def initial_filters(params: FilterParams, q_nb0: Quat, r_n0: Vec3) -> FilterState:
    """At rest on the pad at t = 0: the attitude from the rail (``q_nb0``, the nominal rail's in a flight: what the
    avionics know; replaced by TRIAD or levelled, and the bias by the gyroscope's pad mean, after the pad samples when
    ``params.pad_samples``),
    the position ``r_n0`` [m, NED] (the CG on that rail), at rest."""
    zero = jnp.zeros_like(q_nb0.w)
    still = Vec3(zero, zero, zero)
    nan = zero + jnp.nan
    errors = NavigationErrors(zero, zero, zero, zero, zero, zero, zero, zero, nan, nan, nan, nan, nan)
    return FilterState(zero, initial_attitude(q_nb0, params.attitude), initial_position(r_n0, params.position),
                       still, still, still, still, zero, zero, zero, zero, jnp.zeros_like(zero, dtype=bool), errors,
                       jnp.zeros((*zero.shape, 3), dtype=jnp.int32))  # fmt: skip


def _reference_field(params: FilterParams, r_n: Vec3) -> Vec3:
    """The model's geomagnetic field at ``r_n`` [T, NED], to first order from the pad's."""
    return first_order_field(params.field_n, params.field_gradient, r_n)


def innovation_gate(gate: float | None, nis) -> jnp.ndarray:
    """Whether an update is accepted by its χ² innovation gate: its normalised innovation squared eᵀ S⁻¹ e [-]
    (``nis()``, evaluated only with a gate) at most ``gate`` [-]; always with no gate (None)."""
    return jnp.asarray(True) if gate is None else nis() <= gate


def _covariance_ok(state: FilterState):
    """Both covariances finite with positive variances (a necessary condition of positive definiteness, cheap).

    The failed checks are counted by a dot product, not an elementwise chain: every leaf of the filters' state
    selects on this flag, and XLA's CPU fusion copies an elementwise producer into each consumer (here ~36
    kernels recomputing the covariance updates it depends on), while a dot's result is computed once."""
    p = state.position
    variances = [state.attitude.cov[i, i] for i in range(6)] + [*p.p_rr, *p.p_vv]
    determinants = [rr * vv - rv * rv for rr, rv, vv in zip(p.p_rr, p.p_rv, p.p_vv)]
    checks = [(v > 0.0) & jnp.isfinite(v) for v in variances] + [d > 0.0 for d in determinants]
    failed = ~jnp.concatenate([jnp.stack(checks), jnp.isfinite(state.attitude.cov).ravel()])
    return jnp.ones(failed.shape, jnp.float32) @ failed.astype(jnp.float32) == 0.0


@pytree_dataclass
class Measurements:
    """What the filters read at a tick, in the body frame (FRD): force_b, the accelerometer's specific force
    [m/s²] (its sample of the previous tick), and force_fresh; omega_b, the gyroscope's rates [rad/s], and omega_valid
    (some sample delivered); field_b, the magnetometer's field (any unit: the filter uses its direction), and
    field_fresh; pressure, the barometer's static pressure [Pa], and pressure_fresh; gnss (6,), a GNSS fix's position
    [m] and velocity [m/s] (NED from the pad), and gnss_fresh."""

    force_b: Vec3
    force_fresh: jnp.ndarray
    omega_b: Vec3
    omega_valid: jnp.ndarray
    field_b: Vec3
    field_fresh: jnp.ndarray
    pressure: jnp.ndarray
    pressure_fresh: jnp.ndarray
    gnss: jnp.ndarray
    gnss_fresh: jnp.ndarray


def bus_measurements(av: Avionics, bus: Bus) -> Measurements:
    """The bus's latest samples as the filters read them: the 3-axis sensors turned into the body frame by their
    mountings (known to the avionics)."""
    accel, gyro, mag = bus.accelerometer, bus.gyroscope, bus.magnetometer
    return Measurements(
        to_body(av.accelerometer.rotation, accel.value), accel.fresh, to_body(av.gyroscope.rotation, gyro.value),
        gyro.valid, to_body(av.magnetometer.sensor.rotation, mag.value), mag.fresh, bus.barometer.value[0],
        bus.barometer.fresh, bus.gnss.value, bus.gnss.fresh,
    )  # fmt: skip


def filter_step(params: FilterParams, state: FilterState, m: Measurements, t, moving, idle
                ) -> tuple[Navigation, FilterState]:  # fmt: skip
    """The filters' solution at time t [s] from the measurements ``m``. Position and velocity are propagated from the
    last solution with the accelerometer's sample then (rotated into NED by the attitude then, plus gravity), the
    attitude with the gyroscope's rates then; the magnetometer updates the attitude, the GNSS (after
    ``gnss_after_s``) and the barometer (when on) the position and velocity, each when fresh (and accepted by its gate,
    ``innovation_gate``; the rejections counted). On the pad (``moving`` False: liftoff not yet sensed) the pad sums
    grow; after ``pad_samples`` ticks there the gyroscope's mean sets the bias and TRIAD the attitude (``heading_from_field``;
    else the rail's attitude, held until then, levelled by the accelerometer's mean: ``level``; the rocket is
    at rest: the mean rate is the bias, plus the Earth's rotation, ≤ 7.3e-5 rad/s, which this flat, non-rotating
    Earth does not fly).
    ``idle`` (in a flight: every parachute triggered) or a failed covariance: the filters keep their state. Returns the a-posteriori
    solution (body rates: the gyroscope's less the estimated bias) and the new state (its ``errors`` untouched:
    ``track_errors``)."""
    dt = t - state.t
    acceleration_n = state.attitude.q_nb.rotate(m.force_b) + Vec3(0.0, 0.0, G0)
    position = propagate_position(state.position, acceleration_n, dt, params.position)
    attitude = propagate_attitude(state.attitude, state.omega_measured_b, dt, params.attitude)
    reference = _reference_field(params, position.r_n)
    field_ok = innovation_gate(params.field_gate, lambda: magnetometer_nis(attitude, m.field_b, reference, params.attitude))
    attitude = tree_where(m.field_fresh & field_ok, magnetometer_update(attitude, m.field_b, reference, params.attitude),
                          attitude)  # fmt: skip

    on_pad = ~moving
    pad_ticks = state.pad_ticks + on_pad.astype(state.pad_ticks.dtype)
    pad_force_b = tree_where(on_pad & m.force_fresh, state.pad_force_b + m.force_b, state.pad_force_b)
    pad_field_b = tree_where(on_pad & m.field_fresh, state.pad_field_b + m.field_b, state.pad_field_b)
    pad_rate_b = tree_where(on_pad & m.omega_valid, state.pad_rate_b + m.omega_b, state.pad_rate_b)
    pad_rate_count = state.pad_rate_count + (on_pad & m.omega_valid).astype(state.pad_rate_count.dtype)
    pad_pressure_sum = state.pad_pressure_sum + jnp.where(on_pad & m.pressure_fresh, m.pressure, 0.0)
    pad_pressure_count = state.pad_pressure_count + (on_pad & m.pressure_fresh).astype(state.pad_pressure_count.dtype)
    if params.pad_samples:
        aligned = on_pad & (pad_ticks == params.pad_samples)
        if params.heading_from_field:
            aligned_q_nb = triad(pad_force_b, pad_field_b, reference)
        else:  # the rail's attitude held until levelled (the gyro's raw rates would turn it)
            attitude = tree_where(on_pad & (pad_ticks <= params.pad_samples), state.attitude, attitude)
            aligned_q_nb = level(attitude.q_nb, pad_force_b, params.level_fraction)
        aligned_attitude = initial_attitude(aligned_q_nb, params.attitude)
        bias_b = pad_rate_b * (1.0 / jnp.maximum(pad_rate_count, 1))
        attitude = tree_where(aligned, dataclasses.replace(aligned_attitude, bias_b=bias_b), attitude)

    fix = (t >= params.gnss_after_s) & m.gnss_fresh
    gnss_r, gnss_v = Vec3(*(m.gnss[i] for i in range(3))), Vec3(*(m.gnss[3 + i] for i in range(3)))
    gnss_ok = innovation_gate(params.gnss_gate, lambda: gnss_nis(position, gnss_r, gnss_v, params.position,
                                                                 params.horizontal_only))  # fmt: skip
    fixed = gnss_update(position, gnss_r, gnss_v, params.position, params.horizontal_only)
    position = tree_where(fix & gnss_ok, fixed, position)
    use, height_ok = jnp.asarray(False), jnp.asarray(True)
    if params.barometer:
        pad_pressure = state.pad_pressure_sum / jnp.maximum(state.pad_pressure_count, 1)
        use = m.pressure_fresh & (state.pad_pressure_count > 0) & moving
        height = pressure_height_m(m.pressure, pad_pressure)
        height_ok = innovation_gate(params.altitude_gate, lambda: altitude_nis(position, height, params.position))
        position = tree_where(use & height_ok, altitude_update(position, height, params.position), position)
    rejects = jnp.stack([m.field_fresh & ~field_ok, fix & ~gnss_ok, use & ~height_ok], axis=-1)
    rejected = state.rejected + rejects.astype(state.rejected.dtype)

    omega_measured_b = tree_where(m.omega_valid, m.omega_b, Vec3(0.0, 0.0, 0.0))
    new = FilterState(t, attitude, position, omega_measured_b, pad_force_b, pad_field_b, pad_rate_b,
                      pad_rate_count, pad_pressure_sum, pad_pressure_count, pad_ticks, state.failed, state.errors,
                      rejected)  # fmt: skip
    failing = ~_covariance_ok(new)
    new = tree_where(idle | state.failed | failing, dataclasses.replace(state, t=t), new)  # the last good estimates
    new = dataclasses.replace(new, failed=state.failed | failing)
    omega_b = new.omega_measured_b - new.attitude.bias_b
    return Navigation(new.position.r_n, new.position.v_n, new.attitude.q_nb, omega_b), new


def track_errors(state: FilterState, q_nb: Quat, r_n: Vec3, v_n: Vec3, bias_b: Vec3, window_dt, ascent_dt,
                 after_burnout, after_apogee) -> FilterState:  # fmt: skip
    """``state`` with its ``errors`` updated against the truth at its time: attitude q_nb, CG position r_n [m] and
    velocity v_n [m/s] (NED), the gyroscope's bias bias_b [rad/s, body frame]; window_dt, ascent_dt: the period
    [s] if it counts for the window's or the ascent's totals, else 0; after_burnout, after_apogee: those events have
    happened (their errors are kept at the first such tick)."""
    e, est = state.errors, state
    attitude_error = attitude_error_b(est.attitude.q_nb, q_nb).norm()
    position_error, velocity_error = (est.position.r_n - r_n).norm(), (est.position.v_n - v_n).norm()
    in_window = window_dt > 0.0
    errors = NavigationErrors(
        e.window_time + window_dt,
        e.window_attitude_sq + attitude_error**2 * window_dt,
        jnp.where(in_window, jnp.maximum(e.window_attitude_max, attitude_error), e.window_attitude_max),
        e.window_attitude_nees + attitude_nees(est.attitude, q_nb, bias_b) * window_dt,
        e.window_position_nees + position_nees(est.position, r_n, v_n) * window_dt,
        e.ascent_time + ascent_dt,
        e.ascent_attitude_sq + attitude_error**2 * ascent_dt,
        jnp.where(ascent_dt > 0.0, jnp.maximum(e.ascent_attitude_max, attitude_error), e.ascent_attitude_max),
        jnp.where(in_window, (est.attitude.bias_b - bias_b).norm(), e.bias_error),
        jnp.where(after_burnout & jnp.isnan(e.burnout_position), position_error, e.burnout_position),
        jnp.where(after_burnout & jnp.isnan(e.burnout_velocity), velocity_error, e.burnout_velocity),
        jnp.where(after_apogee & jnp.isnan(e.apogee_position), position_error, e.apogee_position),
        jnp.where(after_apogee & jnp.isnan(e.apogee_velocity), velocity_error, e.apogee_velocity),
    )
    return dataclasses.replace(state, errors=errors)


DIVERGED_ATTITUDE_RAD = 0.1745329251994330  # 10°
"""A flight's navigation has diverged when its attitude estimate is further than this from the truth at some tick of
the controller's active time: 5x the thesis filters' largest window error (median 1.82°, the headwind test's ascent
4.05°, docs/validation.md); 10° of attitude error tilts the inertial acceleration by 17 % of the thrust's."""
DIVERGED_VELOCITY_RAD = 0.03490658503988659  # 2°
"""... or when its velocity error at burnout, over the speed then, exceeds this (an upper bound on the estimated
flight path's direction error, which guidance steers by): above the controller's own tracking error on perfect
navigation (χ 1.47° RMS, Lynx), 8x the thesis filters' median (0.25°, at most 0.55° in 128 flights) and above the
largest of custom_canards' on a gyro-trusting tuning (1.5°), where its ellipse is 1.9x perfect navigation's
(docs/navigation.md). A fraction, not m/s: the same attitude error makes a faster boost's velocity error larger."""
DIVERGED_NEES = 60.0
"""... or when either filter's NEES (6 degrees of freedom) averaged over the controller's active time exceeds this:
10x its χ² mean of 6, the errors √10 ≈ 3.2 times the filter's own σ throughout the window, so its gates and gains
trust an estimate that is wrong (the thesis's tuning averages 1e-4 and 0.22, a consistent tuning 6)."""

DIVERGED_MEANING = (
    f"1: the navigation estimate diverged (attitude error above {math.degrees(DIVERGED_ATTITUDE_RAD):g}° in the "
    f"controller's active time, velocity error at burnout above {math.degrees(DIVERGED_VELOCITY_RAD):g}° of the speed "
    f"then, or a filter's NEES averaged over that time above {DIVERGED_NEES:g}); 0: it did not. Kept in the ellipse: "
    "the flight flew so"
)
"""``navigation_diverged``'s meaning (``sim.outputs.NAVIGATION_METRICS``)."""


def navigation_diverged(summary: dict, burnout_speed_mps) -> jnp.ndarray:
    """1.0 where ``navigation_summary``'s errors exceed ``DIVERGED_ATTITUDE_RAD``, ``DIVERGED_VELOCITY_RAD`` (of the
    true speed at burnout [m/s]) or ``DIVERGED_NEES``, else 0.0 (a NaN, a span that never came, does not count)."""
    over = (summary["attitude_error_max_window_rad"] > DIVERGED_ATTITUDE_RAD) \
        | (summary["velocity_error_burnout_mps"] > DIVERGED_VELOCITY_RAD * burnout_speed_mps) \
        | (summary["attitude_nees_window"] > DIVERGED_NEES) | (summary["position_nees_window"] > DIVERGED_NEES)  # fmt: skip
    return over.astype(summary["attitude_nees_window"].dtype)


def navigation_summary(state: FilterState, burnout_speed_mps) -> dict:
    """The filters' per-flight outputs (``sim.outputs.NAVIGATION_METRICS``); NaN where their span never came, but
    ``navigation_diverged`` (0 or 1; ``burnout_speed_mps``: the true speed at burnout [m/s], NaN before)."""
    e = state.errors

    def mean(total, time):
        return jnp.where(time > 0.0, total / jnp.where(time > 0.0, time, 1.0), jnp.nan)

    summary = {
        "attitude_error_rms_window_rad": jnp.sqrt(mean(e.window_attitude_sq, e.window_time)),
        "attitude_error_max_window_rad": jnp.where(e.window_time > 0.0, e.window_attitude_max, jnp.nan),
        "attitude_error_rms_ascent_rad": jnp.sqrt(mean(e.ascent_attitude_sq, e.ascent_time)),
        "attitude_error_max_ascent_rad": jnp.where(e.ascent_time > 0.0, e.ascent_attitude_max, jnp.nan),
        "gyro_bias_error_window_end_rad_s": e.bias_error,
        "position_error_burnout_m": e.burnout_position,
        "velocity_error_burnout_mps": e.burnout_velocity,
        "position_error_apogee_m": e.apogee_position,
        "velocity_error_apogee_mps": e.apogee_velocity,
        "attitude_nees_window": mean(e.window_attitude_nees, e.window_time),
        "position_nees_window": mean(e.window_position_nees, e.window_time),
    }
    return {**summary, "navigation_diverged": navigation_diverged(summary, burnout_speed_mps)}

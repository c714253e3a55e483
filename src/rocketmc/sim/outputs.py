"""The outputs of a flight: each metric's unit and meaning (``Metric``, ``metric``) and the per-flight summary
with its status code (``flight_summary``), what a campaign stores in ``/outputs``."""

from __future__ import annotations

from typing import NamedTuple

import jax.numpy as jnp

from ..env.atmosphere import MAX_ALTITUDE_M
from ..gnc.airbrakes import airbrake_summary
from ..gnc.control import gnc_summary
from ..gnc.navigation import DIVERGED_MEANING
from .params import FlightParams
from .state import OUTSIDE_TABLES_QBAR_FRACTION, FlightState, Status


class Metric(NamedTuple):
    """An output of a flight: its unit and what it means (stored with each ``/outputs`` dataset)."""

    unit: str
    meaning: str


METRICS: dict[str, Metric] = {
    "apogee_agl_m": Metric("m", "altitude of the CG above the pad at apogee"),
    "apogee_time_s": Metric("s", "time of apogee (t = 0 at rest on the rail, before ignition)"),
    "apogee_north_m": Metric("m", "CG north of the pad at apogee"),
    "apogee_east_m": Metric("m", "CG east of the pad at apogee"),
    "max_mach": Metric("1", "largest Mach number of the flight"),
    "max_dynamic_pressure_pa": Metric("Pa", "largest dynamic pressure of the flight"),
    "max_dynamic_pressure_outside_aero_tables_pa": Metric(
        "Pa", "largest dynamic pressure outside the aerodynamic tables' range, not under a canopy (0: never outside)"
    ),
    "rail_exit_time_s": Metric("s", "time the rear lug leaves the top of the rail"),
    "rail_exit_speed_mps": Metric("m/s", "speed at rail exit"),
    "burnout_time_s": Metric("s", "time the thrust curve ends"),
    "burnout_altitude_agl_m": Metric("m", "altitude of the CG above the pad at burnout"),
    "burnout_speed_mps": Metric("m/s", "speed at burnout"),
    "impact_north_m": Metric("m", "CG north of the pad at impact (the CG back at the pad's altitude)"),
    "impact_east_m": Metric("m", "CG east of the pad at impact"),
    "impact_time_s": Metric("s", "time of impact"),
    "impact_speed_mps": Metric("m/s", "speed at impact"),
    "status": Metric("1", "outcome of the flight, a code of attrs['codes'] (0: ok)"),
}
"""The outputs of ``flight_summary`` by name, its status included, but the parachutes' deploy times
(see ``metric``). Times from t = 0 at rest on the rail; speeds over ground; NaN: the event did not
happen."""

CONTROL_METRICS: dict[str, Metric] = {
    "control_active_time_s": Metric("s", "time the controller was active: inside the guidance window, no parachute triggered"),
    "tracking_error_rms_rad": Metric("rad", "RMS over the active time of χ, the angle from the velocity to the reference direction"),
    "canard_deflection_rms_rad": Metric("rad", "RMS over the active time and the fins of the canard deflections"),
    "canard_deflection_max_rad": Metric("rad", "largest canard deflection of any fin in the flight"),
    "canard_saturated_fraction": Metric("1", "fraction of the active time with a fin command clipped at the servo limit"),
}
"""The outputs a flight with a controller adds (``gnc.control.control_summary``); NaN where it never acted."""

NAVIGATION_METRICS: dict[str, Metric] = {
    "attitude_error_rms_window_rad": Metric("rad", "RMS over the controller's active time of the attitude estimate's error angle"),
    "attitude_error_max_window_rad": Metric("rad", "largest attitude estimation error over the controller's active time"),
    "attitude_error_rms_ascent_rad": Metric("rad", "RMS of the attitude estimation error from the first motion to apogee"),
    "attitude_error_max_ascent_rad": Metric("rad", "largest attitude estimation error from the first motion to apogee"),
    "gyro_bias_error_window_end_rad_s": Metric("rad/s", "norm of the gyro-bias estimate's error at the controller's last active tick"),
    "position_error_burnout_m": Metric("m", "norm of the position estimate's error at the first GNC tick after burnout"),
    "velocity_error_burnout_mps": Metric("m/s", "norm of the velocity estimate's error at the first GNC tick after burnout"),
    "position_error_apogee_m": Metric("m", "norm of the position estimate's error at the first GNC tick after apogee"),
    "velocity_error_apogee_mps": Metric("m/s", "norm of the velocity estimate's error at the first GNC tick after apogee"),
    "attitude_nees_window": Metric("1", "mean over the controller's active time of the MEKF's normalised estimation error squared (6 dof)"),
    "position_nees_window": Metric("1", "mean over the controller's active time of the position/velocity filter's NEES (6 dof)"),
    "navigation_diverged": Metric("1", DIVERGED_MEANING),
}  # fmt: skip
"""The outputs a flight on the navigation filters adds (``gnc.navigation.navigation_summary``); NaN where their span
never came."""

AIRBRAKE_METRICS: dict[str, Metric] = {
    "apogee_error_m": Metric("m", "apogee above the pad less the air brakes' target (NaN: no apogee)"),
    "airbrake_active_time_s": Metric("s", "time the air brakes were allowed: after burnout, below their Mach limit, climbing"),
    "airbrake_deployment_time_s": Metric("s", "the air brakes' deployment integrated over time: seconds at full deployment"),
    "airbrake_saturated_fraction": Metric(
        "1", "fraction of the allowed time fully deployed with the predicted apogee still above the target"
    ),
}
"""The outputs a flight with air brakes adds (``gnc.airbrakes.airbrake_summary``); NaN where they never acted."""

DEPLOY_TIME_SUFFIX = "_deploy_time_s"


def metric(name: str) -> Metric:
    """The ``Metric`` of output ``name``: from ``METRICS`` or a parachute's ``<name>_deploy_time_s``."""
    every = {**METRICS, **CONTROL_METRICS, **NAVIGATION_METRICS, **AIRBRAKE_METRICS}
    if name in every:
        return every[name]
    if not name.endswith(DEPLOY_TIME_SUFFIX):
        raise KeyError(name)
    chute = name.removesuffix(DEPLOY_TIME_SUFFIX)
    return Metric("s", f"time the {chute} parachute deploys: its trigger (apogee or its altitude) plus its delay")


def flight_summary(p: FlightParams, state: FlightState) -> tuple[dict, jnp.ndarray]:
    """Summary metrics (NaN for events that did not happen) and the status code."""
    ev = state.events
    landed = jnp.isfinite(ev.impact_time)

    def when(time, value):
        return jnp.where(jnp.isfinite(time), value, jnp.nan)

    summary = {
        "apogee_agl_m": when(ev.apogee_time, ev.apogee_altitude),
        "apogee_time_s": when(ev.apogee_time, ev.apogee_time),
        "apogee_north_m": when(ev.apogee_time, ev.apogee_north),
        "apogee_east_m": when(ev.apogee_time, ev.apogee_east),
        "max_mach": ev.max_mach,
        "max_dynamic_pressure_pa": ev.max_qbar,
        "max_dynamic_pressure_outside_aero_tables_pa": ev.max_qbar_outside_tables,
        "rail_exit_time_s": when(ev.rail_exit_time, ev.rail_exit_time),
        "rail_exit_speed_mps": when(ev.rail_exit_time, ev.rail_exit_speed),
        "burnout_time_s": when(ev.burnout_time, ev.burnout_time),
        "burnout_altitude_agl_m": when(ev.burnout_time, ev.burnout_altitude),
        "burnout_speed_mps": when(ev.burnout_time, ev.burnout_speed),
        "impact_north_m": when(ev.impact_time, ev.impact_north),
        "impact_east_m": when(ev.impact_time, ev.impact_east),
        "impact_time_s": when(ev.impact_time, ev.impact_time),
        "impact_speed_mps": when(ev.impact_time, ev.impact_speed),
    }
    for chute, trigger_time in zip(p.rocket.parachutes, ev.chute_trigger_times):
        summary[chute.name + DEPLOY_TIME_SUFFIX] = when(trigger_time, trigger_time + chute.delay_s)
    failed = []
    if state.gnc is not None:
        closed_loop, navigation_failed = gnc_summary(p.gnc, state.gnc, summary["burnout_speed_mps"])
        summary.update(closed_loop)
        failed = [] if navigation_failed is None else [navigation_failed]
    if state.airbrakes is not None:
        summary.update(airbrake_summary(p.airbrakes, state.airbrakes, summary["apogee_agl_m"]))
    outside = ev.max_qbar_outside_tables > OUTSIDE_TABLES_QBAR_FRACTION * ev.max_qbar
    too_high = p.environment.site_altitude_m + ev.apogee_altitude > MAX_ALTITUDE_M
    status = jnp.select(
        [*failed, ev.non_finite, ~landed, too_high, outside],
        [*[Status.NAVIGATION_FAILED] * len(failed), Status.NON_FINITE, Status.MAX_TIME, Status.OUTSIDE_ATMOSPHERE,
         Status.OUTSIDE_AERO_TABLES],
        Status.OK,
    )  # fmt: skip
    return summary, status.astype(jnp.int32)

"""The air brakes' flight software: a ballistic apogee prediction from the navigation solution, integral feedback on
the predicted apogee's error, the deployment servo (docs/airbrakes.md).

At each GNC tick t_k the software reads the navigation (``guidance.Navigation``: the truth, or the [gnc]'s navigation
from the sensors), predicts the apogee a point mass would reach from there coasting with the brakes held where they are
(``predicted_apogee_m``: drag along the velocity with the nominal CA(Mach) it knows and the brakes' ΔCA, the ISA's
density, no wind, fixed RK4 steps) and steps the command

    u_k = clip(u_k−1 + K_i·Δt·(ĥ_apogee − h_target), 0, 1)

while the brakes are allowed: from ``allowed_after_s`` after the sensed liftoff (burnout and a margin), below
``max_mach`` (estimated with the ISA's speed of sound), climbing, no parachute out; else u_k = 0 (retracted). The
command's own clip is the anti-windup: it never integrates past a stop. The servo is a first-order lag with an
optional rate limit (``dynamics.servo``, deployment 0 … 1 in place of an angle), so the drag inside a period is its
exact response, as the canards'.

Pure, single-vehicle, scalar components, as ``gnc.control``.
"""

from __future__ import annotations

import jax
import jax.numpy as jnp

from ..dynamics.servo import ServoParams, ServoState, hold_command
from ..env.atmosphere import G0, isa
from ..math import rk4_step, safe_sqrt
from ..math.table import Table, interpolate
from ..pytree import pytree_dataclass, static_field
from .guidance import Navigation

PREDICTION_STEPS = 10
"""RK4 steps of the apogee prediction over its horizon (``predicted_apogee_m``). Against scipy's solve_ivp of the same
model (rtol 1e-11), Lynx's EuRoC coasts from 949, 2000 and 2800 m, retracted, 40 % and fully deployed: within 1.6 m
(0.07 % of a 2.1 km climb; 8 steps 3.4 m, 12 steps 0.9 m), the largest from burnout, where the climb crosses the CA
table's kinks about Mach 0.8-0.9 and RK4 loses its order; a tenth of the navigation's and the drag's errors."""
HORIZON_MARGIN = 1.3
"""The prediction's horizon over the vertical constant-drag coast's time to apogee: the thinning air makes the real
coast longer (Lynx's EuRoC coast from burnout: ~1.1x)."""


@pytree_dataclass
class AirbrakeParams:
    """drag: ``Table`` of the brakes' ΔCA over (deployment, mach), output ``dCA`` (``aero.airbrakes``), what the air
    does; servo: the deployment servo (``limit_rad`` 1: the stop; no offset). What the flight software knows and
    does: known_ca, ``Table`` of the nominal CA at zero incidence over ``mach`` (output ``CA``); reference_area_m2
    [m²]; coast_mass_kg, the nominal rocket after burnout [kg]; site_altitude_m, the pad above mean sea level [m] (its
    ISA); target_apogee_m, above the pad [m]; gain_per_m_s, K_i [1/(m·s)]; allowed_after_s [s since the sensed
    liftoff]; max_mach [-]."""

    drag: Table
    servo: ServoParams
    known_ca: Table
    reference_area_m2: jnp.ndarray
    coast_mass_kg: jnp.ndarray
    site_altitude_m: jnp.ndarray
    target_apogee_m: jnp.ndarray
    gain_per_m_s: jnp.ndarray
    allowed_after_s: jnp.ndarray
    max_mach: jnp.ndarray
    prediction_steps: int = static_field(default=PREDICTION_STEPS)


@pytree_dataclass
class AirbrakeState:
    """servo: the deployment servo's state (deployment at the period start, the command held; scalars, 0 … 1);
    liftoff_time: the tick the navigation first saw the rocket move [s] (inf before); predicted_apogee_m: the last
    prediction above the pad [m] (NaN while not allowed). Totals: active_time [s] allowed; saturated_time [s] allowed
    with the command at full deployment and the prediction still above the target; deployment_time [s], ∫u dt."""

    servo: ServoState
    liftoff_time: jnp.ndarray
    predicted_apogee_m: jnp.ndarray
    active_time: jnp.ndarray
    saturated_time: jnp.ndarray
    deployment_time: jnp.ndarray


def initial_airbrakes(like) -> AirbrakeState:
    """Retracted, before liftoff; ``like`` a scalar of the flight's dtype."""
    zero = jnp.zeros_like(like)
    return AirbrakeState(ServoState(zero, zero), zero + jnp.inf, zero + jnp.nan, zero, zero, zero)


def delta_ca(params: AirbrakeParams, deployment, mach):
    """The brakes' ΔCA [-] at ``deployment`` (0 … 1) and Mach ``mach``, clamped to the table."""
    return interpolate(params.drag, (deployment, mach))[0][0]


def predicted_apogee_m(params: AirbrakeParams, height_m, climb_mps, horizontal_mps, deployment):
    """The apogee above the pad [m] of a point mass (``coast_mass_kg``) coasting from ``height_m`` above the pad at
    ``climb_mps`` up and ``horizontal_mps`` [m/s], drag ½ρV²S(CA(M) + ΔCA(deployment, M)) along the velocity, the
    ISA's air, gravity G0, no wind (``height_m`` itself if not climbing).

    ``prediction_steps`` RK4 steps over a horizon T that covers the coast: the vertical coast's time to apogee under
    quadratic drag at the start's drag constant k, atan(w·√(k/g))/√(k·g) (the air thins as it climbs, so the real coast
    is longer), times ``HORIZON_MARGIN``, at most the drag-free w/g. The crossing of w = 0 is interpolated in its step;
    a climb still going at T adds the drag-free w²/2g."""
    area, mass = params.reference_area_m2, params.coast_mass_kg

    def rates(h, w, u):
        air = isa(params.site_altitude_m + h)
        speed = safe_sqrt(w * w + u * u)
        mach = speed / air.speed_of_sound
        ca = interpolate(params.known_ca, (mach,))[0][0] + delta_ca(params, deployment, mach)
        per_speed = 0.5 * air.density * speed * area * ca / mass  # drag acceleration over the speed [1/s]
        return w, -G0 - per_speed * w, -per_speed * u, per_speed / jnp.maximum(speed, 1e-9)

    climbing = climb_mps > 0.0
    w0 = jnp.where(climbing, climb_mps, 1.0)
    u0 = horizontal_mps + 0.0 * height_m
    k = rates(height_m, w0, u0)[3]  # the drag constant [1/m]: drag acceleration = k·V²
    root = safe_sqrt(k * G0)
    coast = jnp.where(root > 0.0, jnp.arctan(w0 * root / G0) / jnp.where(root > 0.0, root, 1.0), w0 / G0)
    dt = jnp.minimum(HORIZON_MARGIN * coast, w0 / G0) / params.prediction_steps

    def step(carry, _):
        (h, w, u), apogee, crossed = carry
        new, _ = rk4_step(lambda _, y: (rates(*y)[:3], None), 0.0, (h, w, u), dt)
        crossing = ~crossed & (new[1] <= 0.0)
        # w falls nearly linearly inside the step: the time to w = 0 and the height gained, h' = w, to it
        tau = dt * w / jnp.where(crossing, w - new[1], 1.0)
        apogee = jnp.where(crossing, h + 0.5 * w * tau, apogee)
        return (new, apogee, crossed | crossing), None

    start = (height_m + 0.0 * u0, w0, u0)
    ((h_end, w_end, _), apogee, crossed), _ = jax.lax.scan(step, (start, height_m + 0.0 * u0, jnp.asarray(False)), None,
                                                           params.prediction_steps)  # fmt: skip
    return jnp.where(climbing, jnp.where(crossed, apogee, h_end + w_end * w_end / (2.0 * G0)), height_m)


def airbrake_step(params: AirbrakeParams, state: AirbrakeState, nav: Navigation, moving, t, dt,
                  canopy) -> AirbrakeState:  # fmt: skip
    """The air brakes at the GNC tick t [s] (simulation clock) from the navigation solution ``nav``; moving: the
    navigation sees the rocket off the pad (bool); dt: the GNC period [s]; canopy: a parachute triggered (bool).
    Returns the state with the command held for the servo over the period (module docstring)."""
    liftoff_time = jnp.where(jnp.isinf(state.liftoff_time) & moving, t, state.liftoff_time)
    height, climb = -nav.r_n.z, -nav.v_n.z
    horizontal = safe_sqrt(nav.v_n.x * nav.v_n.x + nav.v_n.y * nav.v_n.y)
    speed_of_sound = isa(params.site_altitude_m + height).speed_of_sound
    mach = safe_sqrt(horizontal * horizontal + climb * climb) / speed_of_sound
    allowed = ((t - liftoff_time >= params.allowed_after_s) & (mach < params.max_mach) & (climb > 0.0)
               & ~jnp.asarray(canopy))  # fmt: skip
    deployment = state.servo.deflection_rad
    apogee = predicted_apogee_m(params, height, climb, horizontal, deployment)
    error = apogee - params.target_apogee_m
    stepped = jnp.clip(state.servo.command_rad + params.gain_per_m_s * dt * error, 0.0, 1.0)
    command = jnp.where(allowed, stepped, 0.0)
    active_dt = jnp.where(allowed, dt, 0.0)
    saturated = (command >= 1.0) & (error > 0.0)
    return AirbrakeState(
        hold_command(params.servo, state.servo, command),
        liftoff_time,
        jnp.where(allowed, apogee, jnp.nan),
        state.active_time + active_dt,
        state.saturated_time + jnp.where(saturated, active_dt, 0.0),
        state.deployment_time + deployment * dt,
    )


def airbrake_summary(params: AirbrakeParams, state: AirbrakeState, apogee_agl_m) -> dict:
    """The brakes' per-flight outputs (``sim.outputs.AIRBRAKE_METRICS``), from the flight's apogee above the pad [m]."""
    acted = state.active_time > 0.0
    return {
        "apogee_error_m": apogee_agl_m - params.target_apogee_m,
        "airbrake_active_time_s": state.active_time,
        "airbrake_deployment_time_s": state.deployment_time,
        "airbrake_saturated_fraction": jnp.where(acted, state.saturated_time / jnp.where(acted, state.active_time, 1.0),
                                                 jnp.nan),  # fmt: skip
    }

"""The air brakes' flight software, two laws on the navigation solution (docs/airbrakes.md): a ballistic apogee
prediction with integral feedback on the predicted apogee's error, or the reference-trajectory PI of Skyward's flight
software (``reference_pi_step``); the deployment servo.

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

The reference-trajectory PI (``AirbrakeParams.reference`` set) follows Skyward Experimental Rocketry's air-brake
algorithm (boardcore's ``AirBrakesPI``, MIT licence; the MATLAB simulator's ``control_PID``): reference climb rates
against height, each the coast that ends at the target apogee with the brakes held at one deployment (computed once,
``campaign.airbrakes``); at the first allowed tick the reference nearest the current climb rate at the current height
is chosen and kept; each tick a PI on the climb rate's excess over it, e = w − w_ref(h), adds a vertical drag force

    F = F_ref + K_p·e + I,  I ← I + K_i·Δt·e (held while the command saturates: the anti-windup),

to F_ref, the chosen reference's brakes' vertical drag ½ρ·S·ΔCA(level, M)·w·V here; F, clamped to what the brakes can
give, becomes the deployment whose ΔCA(u, M) gives it (the table inverted at the current Mach).

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
class ReferencePI:
    """The reference-trajectory PI's numbers: reference climb rates ``climb_mps`` (L, H) [m/s] at ``heights_m`` (H,)
    above the pad, reference k computed with the brakes held at ``levels[k]`` (L,) [-]; kp_n_s_per_m, K_p [N/(m/s)];
    ki_n_per_m, K_i [N/m] (N per m/s, per s)."""

    heights_m: jnp.ndarray
    climb_mps: jnp.ndarray
    levels: jnp.ndarray
    kp_n_s_per_m: jnp.ndarray
    ki_n_per_m: jnp.ndarray


@pytree_dataclass
class ReferenceState:
    """The reference-trajectory PI's state: trajectory, the chosen reference's index (−1 before the brakes were first
    allowed); integral_n, the PI's integral term [N]."""

    trajectory: jnp.ndarray
    integral_n: jnp.ndarray


@pytree_dataclass
class AirbrakeParams:
    """drag: ``Table`` of the brakes' ΔCA over (deployment, mach), output ``dCA`` (``aero.airbrakes``), what the air
    does; servo: the deployment servo (``limit_rad`` 1: the stop; no offset). What the flight software knows and
    does: known_ca, ``Table`` of the nominal CA at zero incidence over ``mach`` (output ``CA``); reference_area_m2
    [m²]; coast_mass_kg, the nominal rocket after burnout [kg]; site_altitude_m, the pad above mean sea level [m] (its
    ISA); target_apogee_m, above the pad [m]; gain_per_m_s, the prediction law's K_i [1/(m·s)]; allowed_after_s [s
    since the sensed liftoff]; max_mach [-]; reference: the reference-trajectory PI in place of the prediction law
    (None: the prediction law)."""

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
    reference: ReferencePI | None = None


@pytree_dataclass
class AirbrakeState:
    """servo: the deployment servo's state (deployment at the period start, the command held; scalars, 0 … 1);
    liftoff_time: the tick the navigation first saw the rocket move [s] (inf before); predicted_apogee_m: the last
    prediction above the pad [m] (NaN while not allowed). Totals: active_time [s] allowed; saturated_time [s] allowed
    with the command at full deployment and the law still asking for more drag; deployment_time [s], ∫u dt;
    reference: the reference-trajectory PI's state (None with the prediction law)."""

    servo: ServoState
    liftoff_time: jnp.ndarray
    predicted_apogee_m: jnp.ndarray
    active_time: jnp.ndarray
    saturated_time: jnp.ndarray
    deployment_time: jnp.ndarray
    reference: ReferenceState | None = None


def initial_airbrakes(params: AirbrakeParams, like) -> AirbrakeState:
    """Retracted, before liftoff; ``like`` a scalar of the flight's dtype."""
    zero = jnp.zeros_like(like)
    reference = None if params.reference is None else ReferenceState(jnp.asarray(-1, jnp.int32), zero)
    return AirbrakeState(ServoState(zero, zero), zero + jnp.inf, zero + jnp.nan, zero, zero, zero, reference)


def delta_ca(params: AirbrakeParams, deployment, mach):
    """The brakes' ΔCA [-] at ``deployment`` (0 … 1) and Mach ``mach``, clamped to the table."""
    return interpolate(params.drag, (deployment, mach))[0][0]


def coast_rates(params: AirbrakeParams, h, w, u, deployment):
    """The point-mass coast the flight software models (``predicted_apogee_m``): at ``h`` [m] above the pad, climbing
    ``w`` and moving ``u`` across [m/s], the brakes at ``deployment``: (dh/dt, dw/dt, du/dt) [m/s, m/s²] and the drag
    constant k [1/m] (drag acceleration k·V²)."""
    air = isa(params.site_altitude_m + h)
    speed = safe_sqrt(w * w + u * u)
    mach = speed / air.speed_of_sound
    ca = interpolate(params.known_ca, (mach,))[0][0] + delta_ca(params, deployment, mach)
    per_speed = 0.5 * air.density * speed * params.reference_area_m2 * ca / params.coast_mass_kg  # drag accel / speed [1/s]
    return w, -G0 - per_speed * w, -per_speed * u, per_speed / jnp.maximum(speed, 1e-9)


def predicted_apogee_m(params: AirbrakeParams, height_m, climb_mps, horizontal_mps, deployment):
    """The apogee above the pad [m] of a point mass (``coast_mass_kg``) coasting from ``height_m`` above the pad at
    ``climb_mps`` up and ``horizontal_mps`` [m/s], drag ½ρV²S(CA(M) + ΔCA(deployment, M)) along the velocity, the
    ISA's air, gravity G0, no wind (``height_m`` itself if not climbing).

    ``prediction_steps`` RK4 steps over a horizon T that covers the coast: the vertical coast's time to apogee under
    quadratic drag at the start's drag constant k, atan(w·√(k/g))/√(k·g) (the air thins as it climbs, so the real coast
    is longer), times ``HORIZON_MARGIN``, at most the drag-free w/g. The crossing of w = 0 is interpolated in its step;
    a climb still going at T adds the drag-free w²/2g."""
    rates = lambda h, w, u: coast_rates(params, h, w, u, deployment)  # noqa: E731

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


def reference_pi_step(params: AirbrakeParams, state: ReferenceState, height_m, climb_mps, speed_mps, mach, density,
                      dt, allowed) -> tuple:  # fmt: skip
    """The reference-trajectory PI (module docstring) at ``height_m`` above the pad, climbing ``climb_mps`` at
    ``speed_mps`` [m/s], Mach ``mach``, in air of ``density`` [kg/m³], period ``dt`` [s], the brakes ``allowed``:
    (the deployment command, whether it saturates asking for more drag, the new ``ReferenceState``)."""
    r = params.reference
    references = jax.vmap(lambda climb: jnp.interp(height_m, r.heights_m, climb))(r.climb_mps)
    nearest = jnp.argmin(jnp.abs(references - climb_mps)).astype(state.trajectory.dtype)
    trajectory = jnp.where((state.trajectory < 0) & allowed, nearest, state.trajectory)
    chosen = jnp.maximum(trajectory, 0)
    error = climb_mps - references[chosen]
    per_delta_ca = 0.5 * density * params.reference_area_m2 * jnp.where(climb_mps > 0.0, climb_mps * speed_mps, 1.0)
    integral = state.integral_n + r.ki_n_per_m * dt * error
    wanted = delta_ca(params, r.levels[chosen], mach) + (r.kp_n_s_per_m * error + integral) / per_delta_ca
    deployments = params.drag.axes[0]
    column = jax.vmap(lambda u: delta_ca(params, u, mach))(deployments)
    given = jnp.clip(wanted, column[0], column[-1])
    held = (given != wanted) | ~allowed
    command = jnp.interp(given, column, deployments)
    return command, wanted > column[-1], ReferenceState(trajectory, jnp.where(held, state.integral_n, integral))


def airbrake_step(params: AirbrakeParams, state: AirbrakeState, nav: Navigation, moving, t, dt,
                  canopy) -> AirbrakeState:  # fmt: skip
    """The air brakes at the GNC tick t [s] (simulation clock) from the navigation solution ``nav``; moving: the
    navigation sees the rocket off the pad (bool); dt: the GNC period [s]; canopy: a parachute triggered (bool).
    Returns the state with the command held for the servo over the period (module docstring)."""
    liftoff_time = jnp.where(jnp.isinf(state.liftoff_time) & moving, t, state.liftoff_time)
    height, climb = -nav.r_n.z, -nav.v_n.z
    horizontal = safe_sqrt(nav.v_n.x * nav.v_n.x + nav.v_n.y * nav.v_n.y)
    air = isa(params.site_altitude_m + height)
    speed = safe_sqrt(horizontal * horizontal + climb * climb)
    mach = speed / air.speed_of_sound
    allowed = ((t - liftoff_time >= params.allowed_after_s) & (mach < params.max_mach) & (climb > 0.0)
               & ~jnp.asarray(canopy))  # fmt: skip
    deployment = state.servo.deflection_rad
    if params.reference is None:
        apogee = predicted_apogee_m(params, height, climb, horizontal, deployment)
        error = apogee - params.target_apogee_m
        stepped = jnp.clip(state.servo.command_rad + params.gain_per_m_s * dt * error, 0.0, 1.0)
        wants_more, reference = error > 0.0, None
    else:
        stepped, wants_more, reference = reference_pi_step(params, state.reference, height, climb, speed, mach,
                                                           air.density, dt, allowed)  # fmt: skip
        apogee = jnp.nan
    command = jnp.where(allowed, stepped, 0.0)
    active_dt = jnp.where(allowed, dt, 0.0)
    saturated = (command >= 1.0) & wants_more
    return AirbrakeState(
        hold_command(params.servo, state.servo, command),
        liftoff_time,
        jnp.where(allowed, apogee, jnp.nan),
        state.active_time + active_dt,
        state.saturated_time + jnp.where(saturated, active_dt, 0.0),
        state.deployment_time + deployment * dt,
        reference,
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

"""The air brakes of a campaign's ``[airbrakes]``, designed once on the host when it loads (``loader``): their drag
table, what the flight software knows (the nominal CA(Mach), the coast mass), and the integral gain, from the
nominal flight's point-mass estimate (``gains.point_mass_flight``) where the brakes may first open (docs/airbrakes.md).

The gain: from that state the prediction's apogee retracted, ĥ(0), and fully deployed, ĥ(1), give the brakes'
authority S = ĥ(0) − ĥ(1) [m per unit deployment]; the error e = ĥ − h_target then falls as de/dt = −S·du/dt =
−S·K_i·e, a first-order response of time constant 1/(K_i·S): K_i = 1/(S·response_time_s). S shrinks as the coast
goes on (less of it is left to brake), so the loop slows toward apogee.

The reference-trajectory PI's references (``reference_climbs``): the same point-mass coast integrated backward in
time from the target apogee (climbing 0, moving across at the nominal flight's speed there) with the brakes held at
each level, sampled as climb rate against height. Its gains: about a reference the vertical motion's error obeys
m·ë ≈ −ΔF (m the coast mass), so a PI on it gives m·s² + K_p·s + K_i: K_p = 2ζω·m, K_i = ω²·m (Skyward's 55 N/(m/s) and
5 N/(m/s) per 0.1 s sample on 22 kg: ω ≈ 1.5 rad/s, ζ ≈ 0.83).
"""

from __future__ import annotations

import dataclasses
import math
from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from ..aero.airbrakes import drag_table, panel_table
from ..aero.model import LinearAero, linear_derivatives, simplify
from ..dynamics.servo import ServoParams
from ..gnc.airbrakes import AirbrakeParams, ReferencePI, coast_rates, predicted_apogee_m
from ..math import rk4_step
from ..math.table import Table
from ..sim.params import FlightParams
from .errors import ConfigError
from .gains import ESTIMATE_DT_S, ESTIMATE_HEIGHTS_M, nominal_arrays, point_mass_flight
from .schema import CampaignConfig

KNOWN_CA_MACHS = np.linspace(0.0, 1.2, 25)
"""The Mach grid of the nominal CA the flight software carries."""
REFERENCE_POINTS = 200
"""Heights of each reference, evenly from the pad to the target apogee (15 m apart for a 3 km target)."""
REFERENCE_DT_S = 0.02
"""The backward integration's RK4 step [s]."""


class AirbrakeDesign(NamedTuple):
    """What the brakes' gain was designed from (``design_airbrakes``): window_start_s, when they may first open [s
    since liftoff]; the nominal state there (point-mass estimate): height_m above the pad, climb_mps and
    horizontal_mps [m/s]; nominal_apogee_m, the estimate's apogee without brakes [m]; apogee_retracted_m and
    apogee_deployed_m, the prediction's from that state [m]; target_apogee_m [m]; gain_per_m_s, K_i [1/(m·s)];
    gain_designed, whether the gains were designed (else given); response_time_s [s]. The reference-trajectory PI's
    (``controller`` "reference_pi"): apogee_horizontal_mps, the references' speed across at the apogee [m/s];
    references, their number; kp_n_s_per_m [N/(m/s)] and ki_n_per_m [N/m]; natural_frequency_rad_s [rad/s] and damping
    [-] they were designed for (NaN where they were given)."""

    window_start_s: float
    height_m: float
    climb_mps: float
    horizontal_mps: float
    nominal_apogee_m: float
    apogee_retracted_m: float
    apogee_deployed_m: float
    target_apogee_m: float
    gain_per_m_s: float
    gain_designed: bool
    response_time_s: float
    controller: str = "prediction"
    apogee_horizontal_mps: float = math.nan
    references: int = 0
    kp_n_s_per_m: float = math.nan
    ki_n_per_m: float = math.nan
    natural_frequency_rad_s: float = math.nan
    damping: float = math.nan


def design_airbrakes(config: CampaignConfig, airframe: FlightParams) -> tuple[AirbrakeParams, AirbrakeDesign]:
    """The flight's ``AirbrakeParams`` and their ``AirbrakeDesign`` from the campaign's [airbrakes] and its nominal
    ``airframe`` (``model.airframe_params``). ConfigError naming the field if the nominal flight never climbs in the
    brakes' window, or has no authority there."""
    brakes = config.airbrakes
    aero = airframe.rocket.aero
    simplified = aero if isinstance(aero, LinearAero) else simplify(aero)
    area = float(aero.reference_area_m2)
    site = float(airframe.environment.site_altitude_m)
    if brakes.panels is not None:
        p = brakes.panels
        drag = panel_table(p.count, p.width_m, p.max_extension_m, area, p.cd)
    else:
        drag = drag_table(brakes.table.deployments, brakes.table.machs, brakes.table.delta_ca)
    known = float(simplified.drag_scale) * np.array([linear_derivatives(simplified, m, site)["CA0"] for m in KNOWN_CA_MACHS])
    servo = ServoParams(jnp.asarray(brakes.servo.time_constant_s), jnp.asarray(1.0), jnp.asarray(0.0),
                        None if brakes.servo.rate_limit_per_s is None else jnp.asarray(brakes.servo.rate_limit_per_s))  # fmt: skip
    motor = airframe.rocket.motor
    window_start_s = float(motor.burn_time_s) + brakes.after_burnout_s
    params = AirbrakeParams(
        drag=drag, servo=servo,
        known_ca=Table.from_numpy((KNOWN_CA_MACHS,), known[:, None], ("mach",), ("CA",)),
        reference_area_m2=jnp.asarray(area), coast_mass_kg=jnp.asarray(float(airframe.rocket.dry_mass_kg)),
        site_altitude_m=jnp.asarray(site), target_apogee_m=jnp.asarray(brakes.target_apogee_m),
        gain_per_m_s=jnp.asarray(0.0), allowed_after_s=jnp.asarray(window_start_s), max_mach=jnp.asarray(brakes.max_mach),
    )  # fmt: skip

    times = jnp.arange(0.0, float(motor.ignition_time_s + motor.burn_time_s), ESTIMATE_DT_S)
    _, *arrays = nominal_arrays(airframe, times, jnp.asarray(ESTIMATE_HEIGHTS_M))
    flight = point_mass_flight(airframe, simplified, *map(np.asarray, arrays), window_start_s)
    at = int(np.searchsorted(flight.since_liftoff_s, window_start_s))
    if at >= len(flight.since_liftoff_s) or flight.climb_mps[at] <= 0.0:
        raise ConfigError(f"airbrakes.after_burnout_s: the nominal flight (a point-mass estimate) is not climbing "
                          f"{window_start_s:.2f} s after liftoff, when the brakes may first open")  # fmt: skip
    state = (flight.height_m[at], flight.climb_mps[at], flight.horizontal_mps[at])
    predict = jax.jit(predicted_apogee_m)
    retracted, deployed = (float(predict(params, *state, u)) for u in (0.0, 1.0))
    authority = retracted - deployed
    if not authority > 0.0:
        raise ConfigError("airbrakes: fully deployed, the brakes do not lower the nominal flight's predicted apogee "
                          "(their drag is zero?)")  # fmt: skip
    design = AirbrakeDesign(window_start_s, *map(float, state), float(max(flight.height_m)), retracted, deployed,
                            brakes.target_apogee_m, math.nan, True, brakes.response_time_s, brakes.controller)  # fmt: skip
    pi = brakes.reference_pi
    if pi is None:
        gain = brakes.gain_per_m_s if brakes.gain_per_m_s is not None else 1.0 / (authority * brakes.response_time_s)
        return (dataclasses.replace(params, gain_per_m_s=jnp.asarray(gain)),
                design._replace(gain_per_m_s=gain, gain_designed=brakes.gain_per_m_s is None))  # fmt: skip
    top = int(np.argmax(flight.height_m))
    across = float(flight.horizontal_mps[top])
    climbs = reference_climbs(params, pi.levels, across, 2.0 * (flight.since_liftoff_s[top] - window_start_s))
    mass = float(airframe.rocket.dry_mass_kg)
    designed = pi.kp_n_s_per_m is None or pi.ki_n_per_m is None
    kp = 2.0 * pi.damping * pi.natural_frequency_rad_s * mass if pi.kp_n_s_per_m is None else pi.kp_n_s_per_m
    ki = pi.natural_frequency_rad_s**2 * mass if pi.ki_n_per_m is None else pi.ki_n_per_m
    reference = ReferencePI(jnp.asarray(np.linspace(0.0, brakes.target_apogee_m, REFERENCE_POINTS)), jnp.asarray(climbs),
                            jnp.asarray(pi.levels), jnp.asarray(kp), jnp.asarray(ki))  # fmt: skip
    shown = (pi.natural_frequency_rad_s, pi.damping) if designed else (math.nan, math.nan)
    return dataclasses.replace(params, reference=reference), design._replace(
        gain_designed=designed, apogee_horizontal_mps=across, references=len(pi.levels), kp_n_s_per_m=kp,
        ki_n_per_m=ki, natural_frequency_rad_s=shown[0], damping=shown[1])  # fmt: skip


def reference_climbs(params: AirbrakeParams, levels, apogee_horizontal_mps: float, duration_s: float) -> np.ndarray:
    """The reference-trajectory PI's references (levels, ``REFERENCE_POINTS``): the climb rate [m/s] at heights evenly
    from the pad to the target apogee of the coast (``gnc.airbrakes.coast_rates``) that reaches the target with the
    brakes held at each of ``levels``, moving ``apogee_horizontal_mps`` across there; integrated backward from the
    apogee for ``duration_s`` [s] (heights below where that ends hold its last climb rate)."""
    steps = int(math.ceil(duration_s / REFERENCE_DT_S))

    def backward(level):
        def step(y, _):
            y, _ = rk4_step(lambda _, y: (coast_rates(params, *y, level)[:3], None), 0.0, y, -REFERENCE_DT_S)
            return y, y[:2]

        start = (params.target_apogee_m + 0.0 * level, 0.0 * level, apogee_horizontal_mps + 0.0 * level)
        return jax.lax.scan(step, start, None, steps)[1]

    heights, climbs = map(np.asarray, jax.jit(jax.vmap(backward))(jnp.asarray(levels, dtype=float)))
    target = float(params.target_apogee_m)
    grid = np.linspace(0.0, target, REFERENCE_POINTS)
    rows = []
    for h, w in zip(heights, climbs):
        h, w = np.concatenate([[target], h]), np.concatenate([[0.0], w])
        rows.append(np.interp(grid, h[::-1], w[::-1]))  # the height falls as the backward time runs
    return np.array(rows)


def format_design(design: AirbrakeDesign) -> str:
    """The design as a few lines for ``rocketmc airbrakes design``."""
    d = design
    reach = ("within reach" if d.apogee_deployed_m <= d.target_apogee_m <= d.apogee_retracted_m else
             "below the deployed apogee: the brakes cannot bring the nominal flight down to it"
             if d.target_apogee_m < d.apogee_deployed_m else "above the retracted apogee: the nominal flight falls short")  # fmt: skip
    how = f"designed for a {d.response_time_s:g} s response" if d.gain_designed else "given"
    return "\n".join([
        f"target apogee {d.target_apogee_m:.0f} m above the pad: {reach}",
        f"nominal flight (point-mass estimate): apogee {d.nominal_apogee_m:.0f} m without brakes",
        f"brakes allowed from {d.window_start_s:.2f} s after liftoff: {d.height_m:.0f} m up, climbing "
        f"{d.climb_mps:.1f} m/s, {d.horizontal_mps:.1f} m/s across",
        f"predicted apogee from there: {d.apogee_retracted_m:.0f} m retracted, {d.apogee_deployed_m:.0f} m fully deployed "
        f"(authority {d.apogee_retracted_m - d.apogee_deployed_m:.0f} m)",
        *([f"integral gain K_i = {d.gain_per_m_s:.3g} 1/(m·s) ({how})"] if d.controller == "prediction" else [
            f"reference-trajectory PI: {d.references} reference coasts to the target, {d.apogee_horizontal_mps:.1f} m/s "
            f"across at the apogee",
            f"K_p = {d.kp_n_s_per_m:.4g} N/(m/s), K_i = {d.ki_n_per_m:.4g} N/m " + (
                f"(designed for ω {d.natural_frequency_rad_s:g} rad/s, ζ {d.damping:g})" if d.gain_designed else "(given)"),
        ]),
    ])  # fmt: skip

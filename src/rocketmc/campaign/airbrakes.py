"""The air brakes of a campaign's ``[airbrakes]``, designed once on the host when it loads (``loader``): their drag
table, what the flight software knows (the nominal CA(Mach), the coast mass), and the integral gain, from the
nominal flight's point-mass estimate (``gains.point_mass_flight``) where the brakes may first open (docs/airbrakes.md).

The gain: from that state the prediction's apogee retracted, ĥ(0), and fully deployed, ĥ(1), give the brakes'
authority S = ĥ(0) − ĥ(1) [m per unit deployment]; the error e = ĥ − h_target then falls as de/dt = −S·du/dt =
−S·K_i·e, a first-order response of time constant 1/(K_i·S): K_i = 1/(S·response_time_s). S shrinks as the coast
goes on (less of it is left to brake), so the loop slows toward apogee.
"""

from __future__ import annotations

import dataclasses
from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from ..aero.airbrakes import drag_table, panel_table
from ..aero.model import LinearAero, linear_derivatives, simplify
from ..dynamics.servo import ServoParams
from ..gnc.airbrakes import AirbrakeParams, predicted_apogee_m
from ..math.table import Table
from ..sim.params import FlightParams
from .errors import ConfigError
from .gains import ESTIMATE_DT_S, ESTIMATE_HEIGHTS_M, nominal_arrays, point_mass_flight
from .schema import CampaignConfig

KNOWN_CA_MACHS = np.linspace(0.0, 1.2, 25)
"""The Mach grid of the nominal CA the flight software carries."""


class AirbrakeDesign(NamedTuple):
    """What the brakes' gain was designed from (``design_airbrakes``): window_start_s, when they may first open [s
    since liftoff]; the nominal state there (point-mass estimate): height_m above the pad, climb_mps and
    horizontal_mps [m/s]; nominal_apogee_m, the estimate's apogee without brakes [m]; apogee_retracted_m and
    apogee_deployed_m, the prediction's from that state [m]; target_apogee_m [m]; gain_per_m_s, K_i [1/(m·s)];
    gain_designed, whether K_i was designed (else given); response_time_s [s]."""

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
    gain = brakes.gain_per_m_s if brakes.gain_per_m_s is not None else 1.0 / (authority * brakes.response_time_s)
    design = AirbrakeDesign(window_start_s, *map(float, state), float(max(flight.height_m)), retracted, deployed,
                            brakes.target_apogee_m, gain, brakes.gain_per_m_s is None, brakes.response_time_s)  # fmt: skip
    return dataclasses.replace(params, gain_per_m_s=jnp.asarray(gain)), design


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
        f"integral gain K_i = {d.gain_per_m_s:.3g} 1/(m·s) ({how})",
    ])  # fmt: skip

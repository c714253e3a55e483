"""Faults of one flight (docs/faults.md): the canard servos, the air brakes and the sensors as they fail, on the truth.

A fault acts from the first GNC period that starts at or after its time (its time ``inf``: never): the servos'
state and time constant are set at the period start, the sensors sample at the period start. What the navigation
filters know of the sensors is unchanged: they meet the fault as they would in flight.

Pure, single-vehicle; every fault is optional (None: absent, and nothing of it is traced).
"""

from __future__ import annotations

import dataclasses

import jax.numpy as jnp

from ..dynamics.servo import ServoParams, ServoState
from ..pytree import pytree_dataclass
from ..sensors.avionics import Avionics


@pytree_dataclass
class StuckCanard:
    """time_s: from when [s] (inf: never); fin (n,) bool: the stuck fin; angle_rad: the deflection it is stuck at
    [rad], without the rigging offset (None: where it was at the fault; a static choice)."""

    time_s: jnp.ndarray
    fin: jnp.ndarray
    angle_rad: jnp.ndarray | None = None


@pytree_dataclass
class SlowCanard:
    """time_s: from when [s] (inf: never); fin (n,) bool: the slow fin; factor: its time constant's multiplier [-]."""

    time_s: jnp.ndarray
    fin: jnp.ndarray
    factor: jnp.ndarray


@pytree_dataclass
class StuckAirbrakes:
    """time_s: from when [s] (inf: never); deployment: where they jam, 0 … 1 (None: where they were; a static
    choice)."""

    time_s: jnp.ndarray
    deployment: jnp.ndarray | None = None


@pytree_dataclass
class GnssOutage:
    """No fix is taken from start_s to end_s [s] (inf: never)."""

    start_s: jnp.ndarray
    end_s: jnp.ndarray


@pytree_dataclass
class SensorStep:
    """time_s: from when [s] (inf: never); value (3,): what is added from then on, in the sensor's frame and unit
    (SI): the magnetometer's hard iron [T], a gyroscope's [rad/s] or accelerometer's [m/s²] bias."""

    time_s: jnp.ndarray
    value: jnp.ndarray


@pytree_dataclass
class Faults:
    """The faults a flight can have, each None where the campaign has none (nothing traced for it)."""

    stuck_canard: StuckCanard | None = None
    slow_canard: SlowCanard | None = None
    gnss_outage: GnssOutage | None = None
    magnetometer_step: SensorStep | None = None
    gyroscope_bias_jump: SensorStep | None = None
    accelerometer_bias_jump: SensorStep | None = None
    stuck_airbrakes: StuckAirbrakes | None = None

    @property
    def servos(self) -> bool:
        """Some fault acts on the servos (static)."""
        return self.stuck_canard is not None or self.slow_canard is not None

    @property
    def sensors(self) -> bool:
        """Some fault acts on the sensors (static)."""
        return any(f is not None for f in (self.gnss_outage, self.magnetometer_step, self.gyroscope_bias_jump,
                                           self.accelerometer_bias_jump))  # fmt: skip


def faulty_servos(faults: Faults, params: ServoParams, state: ServoState, t) -> tuple[ServoParams, ServoState]:
    """The servos over the period starting at ``t`` [s], their command held (``hold_command``): a slow fin's time
    constant multiplied by its factor (per fin then), a stuck fin's command set to its deflection, which then stays
    as it is bit for bit (δ_cmd + (δ − δ_cmd)·e = δ), or both set to its stuck angle."""
    slow, stuck = faults.slow_canard, faults.stuck_canard
    if slow is not None:
        factor = jnp.where(slow.fin & (t >= slow.time_s), slow.factor, 1.0)
        params = dataclasses.replace(params, time_constant_s=params.time_constant_s * factor)
    if stuck is not None:
        now = stuck.fin & (t >= stuck.time_s)
        deflection = state.deflection_rad if stuck.angle_rad is None else jnp.where(now, stuck.angle_rad,
                                                                                    state.deflection_rad)  # fmt: skip
        state = ServoState(deflection, jnp.where(now, deflection, state.command_rad))
    return params, state


def stuck_airbrakes(stuck: StuckAirbrakes, state: ServoState, t) -> ServoState:
    """The air brakes' servo over the period starting at ``t`` [s], its command held: from the fault on, the command set
    to the deployment, which then stays as it is bit for bit (as a stuck canard), or both set to the jammed deployment."""
    now = t >= stuck.time_s
    deployment = state.deflection_rad if stuck.deployment is None else jnp.where(now, stuck.deployment,
                                                                                  state.deflection_rad)  # fmt: skip
    return ServoState(deployment, jnp.where(now, deployment, state.command_rad))


def faulty_sensors(faults: Faults, av: Avionics, t) -> Avionics:
    """The sensors sampled at ``t`` [s]: no GNSS fix in an outage (its first fix pushed past now), the magnetometer's
    hard iron and the inertial sensors' biases with their steps once they happened."""
    outage, field = faults.gnss_outage, faults.magnetometer_step
    if outage is not None:
        dark = (t >= outage.start_s) & (t < outage.end_s)
        av = dataclasses.replace(av, gnss=dataclasses.replace(av.gnss, first_fix_s=jnp.where(dark, jnp.inf,
                                                                                             av.gnss.first_fix_s)))  # fmt: skip
    if field is not None:
        mag = av.magnetometer
        av = dataclasses.replace(av, magnetometer=dataclasses.replace(mag, hard_iron=mag.hard_iron + _since(field, t)))
    for name in ("gyroscope", "accelerometer"):
        if (jump := getattr(faults, f"{name}_bias_jump")) is not None:
            mounted = getattr(av, name)
            channel = dataclasses.replace(mounted.channel, bias=mounted.channel.bias + _since(jump, t))
            av = dataclasses.replace(av, **{name: dataclasses.replace(mounted, channel=channel)})
    return av


def _since(step: SensorStep, t):
    """The step's value once it happened (at ``t`` [s]), else zeros."""
    return jnp.where(t >= step.time_s, step.value, 0.0)

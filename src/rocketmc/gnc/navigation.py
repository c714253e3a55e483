"""Navigation from the avionics bus. For now ``navigation = "sensors"``: raw sensors, no filter (issue 18 adds
the MEKF and the position/velocity Kalman filter), to show what raw sensors do to the closed loop.

Raw sensors: body rates from the gyroscope, the launch attitude propagated by the gyroscope's rates (no
correction: its bias and noise integrate), position and velocity from the GNSS, held between fixes (zero
before the first fix), liftoff from the accelerometer.
"""

from __future__ import annotations

import jax.numpy as jnp

from ..env.atmosphere import G0
from ..math import Quat, Vec3
from ..pytree import pytree_dataclass
from ..sensors.avionics import Avionics, Bus
from .guidance import Navigation

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


def rotation_step(omega_b: Vec3, dt) -> Quat:
    """The quaternion of a rotation at constant body rates ω [rad/s] over dt [s]: (cos(θ/2), sin(θ/2)·ω/|ω|),
    θ = |ω|·dt (exact for constant rates; smooth at ω = 0)."""
    angle = omega_b.norm() * dt
    half_sinc = 0.5 * dt * jnp.sinc(0.5 * angle / jnp.pi)  # sin(θ/2)/|ω|
    return Quat(jnp.cos(0.5 * angle), omega_b.x * half_sinc, omega_b.y * half_sinc, omega_b.z * half_sinc)


def _to_body(rotation, value) -> Vec3:
    """A sensor-frame (3,) value in the body frame: the mounting rotation (body → sensor) transposed."""
    return Vec3(*(sum(rotation[j, i] * value[j] for j in range(3)) for i in range(3)))


def dead_reckoning(av: Avionics, state: DeadReckoning, bus: Bus, t) -> tuple[Navigation, DeadReckoning]:
    """The raw-sensor solution at time t [s]: the attitude propagated from the last solution with its rates,
    then the bus's gyroscope rates and GNSS fix (the last ones held when none is fresh)."""
    q_nb = (state.q_nb * rotation_step(state.omega_b, t - state.t)).normalized()
    gyro, gnss = bus.gyroscope, bus.gnss
    omega_b = _to_body(av.gyroscope.rotation, gyro.value)
    omega_b = Vec3(*(jnp.where(gyro.valid, w, 0.0) for w in omega_b))
    r_n = Vec3(*(jnp.where(gnss.fresh, gnss.value[i], held) for i, held in enumerate(state.r_n)))
    v_n = Vec3(*(jnp.where(gnss.fresh, gnss.value[3 + i], held) for i, held in enumerate(state.v_n)))
    return Navigation(r_n, v_n, q_nb, omega_b), DeadReckoning(t, q_nb, omega_b, r_n, v_n)


def liftoff_sensed(av: Avionics, bus: Bus):
    """True when the accelerometer reads more than ``LIFTOFF_SPECIFIC_FORCE_MPS2`` along the rocket's axis."""
    accel = bus.accelerometer
    return accel.valid & (_to_body(av.accelerometer.rotation, accel.value).x > LIFTOFF_SPECIFIC_FORCE_MPS2)

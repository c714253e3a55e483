"""Three-vectors and Hamilton quaternions held as named scalar components.

Each component is a JAX scalar for one vehicle (a batch array once ``vmap``-ed), so the hot
right-hand side never stacks or slices tiny arrays: see docs/sharp-bits.md for the measured
reason. Quaternions are scalar-first ``[w, x, y, z]``; ``q_nb`` rotates body vectors into NED.
"""

from __future__ import annotations

from typing import NamedTuple

import jax.numpy as jnp

from .safe import safe_sqrt


class Vec3(NamedTuple):
    """A 3-vector in one frame; the frame is named by the variable (``v_n``, ``omega_b``)."""

    x: jnp.ndarray
    y: jnp.ndarray
    z: jnp.ndarray

    def __add__(self, other: Vec3) -> Vec3:  # type: ignore[override]
        return Vec3(self.x + other.x, self.y + other.y, self.z + other.z)

    def __sub__(self, other: Vec3) -> Vec3:
        return Vec3(self.x - other.x, self.y - other.y, self.z - other.z)

    def __neg__(self) -> Vec3:
        return Vec3(-self.x, -self.y, -self.z)

    def __mul__(self, s) -> Vec3:  # type: ignore[override]
        return Vec3(self.x * s, self.y * s, self.z * s)

    __rmul__ = __mul__

    def dot(self, other: Vec3) -> jnp.ndarray:
        return self.x * other.x + self.y * other.y + self.z * other.z

    def cross(self, other: Vec3) -> Vec3:
        return Vec3(
            self.y * other.z - self.z * other.y,
            self.z * other.x - self.x * other.z,
            self.x * other.y - self.y * other.x,
        )

    def norm(self) -> jnp.ndarray:
        return safe_sqrt(self.dot(self))

    def to_array(self) -> jnp.ndarray:
        """(3,) array (for tests and host code; avoid inside the right-hand side)."""
        return jnp.stack([self.x, self.y, self.z], axis=-1)

    @classmethod
    def from_array(cls, a) -> Vec3:
        a = jnp.asarray(a)
        return cls(a[..., 0], a[..., 1], a[..., 2])

    @classmethod
    def zeros(cls, like=0.0) -> Vec3:
        z = jnp.zeros_like(jnp.asarray(like, dtype=float))
        return cls(z, z, z)


class Quat(NamedTuple):
    """Hamilton unit quaternion, scalar first."""

    w: jnp.ndarray
    x: jnp.ndarray
    y: jnp.ndarray
    z: jnp.ndarray

    def __mul__(self, o: Quat) -> Quat:  # type: ignore[override]
        """Hamilton product ``self ⊗ o``."""
        return Quat(
            self.w * o.w - self.x * o.x - self.y * o.y - self.z * o.z,
            self.w * o.x + self.x * o.w + self.y * o.z - self.z * o.y,
            self.w * o.y - self.x * o.z + self.y * o.w + self.z * o.x,
            self.w * o.z + self.x * o.y - self.y * o.x + self.z * o.w,
        )

    def conj(self) -> Quat:
        return Quat(self.w, -self.x, -self.y, -self.z)

    def norm(self) -> jnp.ndarray:
        return safe_sqrt(self.w**2 + self.x**2 + self.y**2 + self.z**2)

    def normalized(self) -> Quat:
        n = self.norm()
        return Quat(self.w / n, self.x / n, self.y / n, self.z / n)

    def rotate(self, v: Vec3) -> Vec3:
        """``q ⊗ v ⊗ q*``: a body vector expressed in the world frame when ``self = q_nb``."""
        u = Vec3(self.x, self.y, self.z)
        t = u.cross(v) * 2.0
        return v + t * self.w + u.cross(t)

    def rotate_inverse(self, v: Vec3) -> Vec3:
        """``q* ⊗ v ⊗ q``: a world vector expressed in the body frame when ``self = q_nb``."""
        return self.conj().rotate(v)

    def derivative(self, omega_b: Vec3) -> Quat:
        """Kinematics ``dq/dt = ½ q ⊗ [0, ω_b]`` with ω_b the body rate in the body frame [rad/s]."""
        d = self * Quat(jnp.zeros_like(omega_b.x), omega_b.x, omega_b.y, omega_b.z)
        return Quat(0.5 * d.w, 0.5 * d.x, 0.5 * d.y, 0.5 * d.z)

    def to_array(self) -> jnp.ndarray:
        return jnp.stack([self.w, self.x, self.y, self.z], axis=-1)

    @classmethod
    def from_array(cls, a) -> Quat:
        a = jnp.asarray(a)
        return cls(a[..., 0], a[..., 1], a[..., 2], a[..., 3])

    @classmethod
    def from_euler(cls, yaw, pitch, roll) -> Quat:
        """``q_nb`` from aerospace 3-2-1 Euler angles (yaw ψ about z, pitch θ about y, roll φ about x) [rad]."""
        cy, sy = jnp.cos(yaw / 2), jnp.sin(yaw / 2)
        cp, sp = jnp.cos(pitch / 2), jnp.sin(pitch / 2)
        cr, sr = jnp.cos(roll / 2), jnp.sin(roll / 2)
        return cls(
            cr * cp * cy + sr * sp * sy,
            sr * cp * cy - cr * sp * sy,
            cr * sp * cy + sr * cp * sy,
            cr * cp * sy - sr * sp * cy,
        )

    def to_euler(self):
        """(yaw, pitch, roll) [rad], 3-2-1 sequence; inverse of ``from_euler`` away from ±90° pitch."""
        w, x, y, z = self
        yaw = jnp.arctan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
        pitch = jnp.arcsin(jnp.clip(2 * (w * y - z * x), -1.0, 1.0))
        roll = jnp.arctan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y))
        return yaw, pitch, roll

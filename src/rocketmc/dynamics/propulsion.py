"""Solid motor: thrust curve, propellant consumption and a hollow-cylinder grain.

The mass flow follows the thrust, ṁ = F·m_p0/I_tot (equivalently F/(g0·Isp) with
Isp = I_tot/(g0·m_p0)), so the motor burns exactly its propellant over the curve. The grain is a
hollow cylinder burning outward from its core (outer diameter and length fixed), which sets the
propellant inertia; its centre of mass stays at the grain centre.
"""

from __future__ import annotations

from pathlib import Path
from xml.etree import ElementTree

import jax.numpy as jnp
import numpy as np

from ..math import interp1d
from ..pytree import pytree_dataclass


@pytree_dataclass
class Motor:
    """A solid motor mounted on the body axis; body-frame x positions [m] from the reference point.

    time_s, thrust_n: (K,) thrust curve from ignition [s, N], starting at (0, 0)
    impulse_ns:       (K,) cumulative impulse at each curve point [N·s]
    ignition_time_s:  ignition time after the start of the simulation [s]
    propellant_mass_kg: initial propellant mass [kg]
    grain_outer_diameter_m, grain_inner_diameter_m, grain_length_m: initial grain geometry [m]
    grain_center_x_m: body-frame x of the grain's centre [m]
    nozzle_x_m: body-frame x of the nozzle exit [m]
    """

    time_s: jnp.ndarray
    thrust_n: jnp.ndarray
    impulse_ns: jnp.ndarray
    ignition_time_s: jnp.ndarray
    propellant_mass_kg: jnp.ndarray
    grain_outer_diameter_m: jnp.ndarray
    grain_inner_diameter_m: jnp.ndarray
    grain_length_m: jnp.ndarray
    grain_center_x_m: jnp.ndarray
    nozzle_x_m: jnp.ndarray

    @property
    def burn_time_s(self):
        """Duration of the thrust curve [s]."""
        return self.time_s[-1]

    @property
    def total_impulse_ns(self):
        return self.impulse_ns[-1]


class ThrustCurveError(ValueError):
    """A thrust curve file that cannot be read."""


def _rse_rows(path: Path) -> list[tuple[float, float]]:
    """(time, thrust) of the first engine of a RockSim ``.rse`` file (``<eng-data t= f=>``)."""
    try:
        root = ElementTree.parse(path).getroot()
    except ElementTree.ParseError as err:
        raise ThrustCurveError(f"{path}: not a readable RockSim .rse file ({err})") from None
    engine = root.find(".//engine")
    if engine is None:
        raise ThrustCurveError(f"{path}: no <engine> element")
    try:
        return [(float(p.attrib["t"]), float(p.attrib["f"])) for p in engine.iter("eng-data")]
    except (KeyError, ValueError):
        raise ThrustCurveError(f"{path}: an <eng-data> point lacks a numeric t or f") from None


def _text_rows(path: Path) -> list[tuple[float, float]]:
    """(time, thrust) of a RASP ``.eng`` file (its first non-comment line is the header) or a CSV."""
    try:
        text = path.read_bytes().decode("utf-8-sig")  # -sig: spreadsheets often start with a BOM
    except UnicodeDecodeError:
        raise ThrustCurveError(f"{path}: not a UTF-8 text file") from None
    rows = []
    header_seen = path.suffix.lower() != ".eng"
    for line in text.splitlines():
        line = line.split(";")[0].strip()
        if not line:
            continue
        if not header_seen:  # RASP: the first non-comment line describes the motor
            header_seen = True
            continue
        parts = line.replace(",", " ").split()
        try:
            rows.append((float(parts[0]), float(parts[1])))
        except (ValueError, IndexError):
            if rows:  # a CSV header is allowed only before the data
                raise ThrustCurveError(f"{path}: cannot read the line {line!r}") from None
    return rows


def read_thrust_curve(path: str | Path) -> tuple[np.ndarray, np.ndarray]:
    """Read a RASP ``.eng``, a RockSim ``.rse`` or a two-column CSV (time [s], thrust [N]).

    Returns (time, thrust) arrays starting at (0, 0): RASP curves leave the ignition point
    implicit, so it is added when the first time is positive. ``ThrustCurveError`` naming the file
    and what is wrong, also for a file that cannot be read or is not text.
    """
    path = Path(path)
    if not path.is_file():
        raise ThrustCurveError(f"thrust curve file not found: {path}")
    try:
        rows = _rse_rows(path) if path.suffix.lower() == ".rse" else _text_rows(path)
    except OSError as err:
        raise ThrustCurveError(f"{path}: cannot be read ({err.strerror or err})") from None
    if len(rows) < 2:
        raise ThrustCurveError(f"{path}: fewer than two thrust points")
    t, f = np.array(rows, dtype=float).T
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(f))):
        raise ThrustCurveError(f"{path}: times and thrusts must be finite numbers")
    if np.any(np.diff(t) <= 0) or t[0] < 0 or np.any(f < 0):
        raise ThrustCurveError(f"{path}: times must increase from >= 0 and thrust must be >= 0")
    if t[0] > 0:
        t, f = np.concatenate([[0.0], t]), np.concatenate([[0.0], f])
    with np.errstate(over="ignore"):
        total_impulse_ns = cumulative_impulse(t, f)[-1]
    if not 0.0 < total_impulse_ns < np.inf:  # the mass flow is F·m_p0/I_tot
        raise ThrustCurveError(f"{path}: the total impulse must be positive and finite, got {total_impulse_ns:g} N·s")
    return t, f


def cumulative_impulse(time_s: np.ndarray, thrust_n: np.ndarray) -> np.ndarray:
    """Trapezoidal cumulative impulse at each curve point (exact for the linear curve) [N·s]; traceable."""
    return jnp.concatenate([jnp.zeros(1), jnp.cumsum(jnp.diff(time_s) * 0.5 * (thrust_n[1:] + thrust_n[:-1]))])


def thrust(motor: Motor, t):
    """Thrust [N] at simulation time ``t`` [s]; zero before ignition and after burnout."""
    tau = t - motor.ignition_time_s
    burning = (tau >= 0.0) & (tau <= motor.burn_time_s)
    return jnp.where(burning, interp1d(tau, motor.time_s, motor.thrust_n), 0.0)


def delivered_impulse(motor: Motor, t):
    """Impulse delivered up to simulation time ``t`` [N·s], exact for the piecewise-linear curve."""
    tau = jnp.clip(t - motor.ignition_time_s, 0.0, motor.burn_time_s)
    k = motor.time_s.shape[0]
    i = jnp.clip(jnp.searchsorted(motor.time_s, tau, side="right", method="compare_all") - 1, 0, k - 2)
    t0, t1, f0, f1 = motor.time_s[i], motor.time_s[i + 1], motor.thrust_n[i], motor.thrust_n[i + 1]
    f_tau = f0 + (tau - t0) / (t1 - t0) * (f1 - f0)  # thrust at tau, from the segment already found
    return motor.impulse_ns[i] + 0.5 * (tau - t0) * (f0 + f_tau)


def propellant_mass(motor: Motor, t):
    """Propellant left at simulation time ``t`` [kg] (clamped at 0 against rounding after burnout)."""
    return jnp.maximum(motor.propellant_mass_kg * (1.0 - delivered_impulse(motor, t) / motor.total_impulse_ns), 0.0)


def grain_inertia(motor: Motor, m_prop):
    """Axial and transverse inertia [kg·m²] of the grain about its own centre, for mass ``m_prop``.

    The core grows as the propellant burns: d_in² = d_out² − 4 m/(ρ π L), with the density ρ set by
    the initial geometry and mass; I_xx = m (r_out² + r_in²)/2, I_yy = m (3 (r_out² + r_in²) + L²)/12.
    """
    d_out, length = motor.grain_outer_diameter_m, motor.grain_length_m
    area0 = 0.25 * jnp.pi * (d_out**2 - motor.grain_inner_diameter_m**2)
    d_in_sq = d_out**2 - (m_prop / motor.propellant_mass_kg) * area0 * 4.0 / jnp.pi
    r_sq_sum = 0.25 * (d_out**2 + d_in_sq)
    return 0.5 * m_prop * r_sq_sum, m_prop * (3.0 * r_sq_sum + length**2) / 12.0

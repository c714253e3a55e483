"""Dryden continuous turbulence (MIL-F-8785C §3.7 / MIL-HDBK-1797), sampled along the flight path.

The gust velocities are the outputs of shaping filters driven by white noise, with Taylor's
frozen-field time scale L/V. V is the airspeed, the speed through the local air gust included: a
canopy sinking at 6 m/s through a 5 m/s updraft still samples new air at 6 m/s, where the speed
relative to the mean wind alone (1 m/s) would freeze it inside the updraft for minutes (seen: a
lynx_nominal flight hovered 150 s). The standard's spectra, one-sided in
temporal frequency ω [rad/s] (∫₀^∞ Φ dω = σ²), with τ = L/V:

    Φ_u(ω) = σ_u² (2τ/π) / (1 + τ²ω²)
    Φ_v(ω) = σ_v² (τ/π) (1 + 3τ²ω²) / (1 + τ²ω²)²    (and Φ_w with σ_w, L_w)

u is an Ornstein–Uhlenbeck process; v and w are the sum of two states of the repeated pole 1/τ, kept
normalised to unit stationary variance (their correlation is 1/√2) so that changing σ with altitude
needs no rescaling. Each step is the **exact discretisation** of these stochastic systems for the step
length and the τ of the step's start: transition e^{Ah} and noise covariance P∞ − e^{Ah} P∞ e^{Aᵀh},
so the sampled series has exactly the continuous process's variance and (aliased) spectrum.

Regimes (h above ground): below 1000 ft the low-altitude model, its axes u along the horizontal mean
wind, w down; above 2000 ft the medium/high-altitude model (isotropic, L = 1750 ft, σ from the
probability-of-exceedance table), in body axes; in between both filter sets run and their outputs are
blended with weights √(1−λ), √λ, λ = (h − 1000 ft)/1000 ft, so the variance interpolates linearly.

The angular gust components (p_g, q_g, r_g) are left out: for a 0.15 m body their bandwidth,
πV/(4b), is hundreds of Hz, far above the 50 Hz step, and the spatial gust gradient they stand for
changes the moments by a few percent of the translational gusts' within the rocket's band (see
docs/validation.md).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from ..math import Quat, Vec3, safe_sqrt
from ..math.table import Table, interpolate
from ..pytree import pytree_dataclass

FT = 0.3048  # [m]
KNOT = 1852.0 / 3600.0  # [m/s]
LOW_ALTITUDE_TOP_M = 1000.0 * FT
HIGH_ALTITUDE_BASE_M = 2000.0 * FT
HIGH_ALTITUDE_SCALE_M = 1750.0 * FT
LOW_ALTITUDE_FLOOR_M = 10.0 * FT  # the low-altitude formulas' lower limit

SEVERITIES = ("none", "light", "moderate", "severe")
"""Severity codes 0..3. Light, moderate, severe: the 10⁻², 10⁻³ and 10⁻⁵ exceedance curves at high
altitude and W20 = 15, 30, 45 kt at low altitude (MIL-F-8785C)."""
SEVERITY_W20_MPS = tuple(kt * KNOT for kt in (0.0, 15.0, 30.0, 45.0))

# MIL-F-8785C's high-altitude intensity figure (p. 49), as tabulated in JSBSim's FGWinds: σ [ft/s]
# vs altitude [ft] for the exceedance curves 10⁻², 10⁻³, 10⁻⁵, after a zero row for "none".
_TABLE_ALTITUDE_FT = (500.0, 1750.0, 3750.0, 7500.0, 15000.0, 25000.0, 35000.0, 45000.0, 55000.0, 65000.0,
                      75000.0, 80000.0)  # fmt: skip
_TABLE_SIGMA_FTPS = (
    (0.0,) * 12,
    (6.6, 6.9, 7.4, 6.7, 4.6, 2.7, 0.4, 0.0, 0.0, 0.0, 0.0, 0.0),
    (8.6, 9.6, 10.6, 10.1, 8.0, 6.6, 5.0, 4.2, 2.7, 0.0, 0.0, 0.0),
    (15.6, 17.6, 23.0, 23.6, 22.1, 20.0, 16.0, 15.1, 12.1, 7.9, 6.2, 5.1),
)
HIGH_ALTITUDE_SIGMA = Table.from_numpy(
    (np.arange(len(SEVERITIES), dtype=float), np.asarray(_TABLE_ALTITUDE_FT) * FT),
    np.asarray(_TABLE_SIGMA_FTPS)[..., None] * FT,
    ("severity", "altitude_agl_m"),
    ("sigma_mps",),
)
"""σ [m/s] of the medium/high-altitude model over (severity code, height above ground [m]); constant
beyond 80 000 ft. A fractional severity interpolates between the curves."""

_SQRT2 = math.sqrt(2.0)
_V_MIX = ((1.0 - math.sqrt(3.0)) / 2.0, math.sqrt(1.5))  # output weights of the two v/w states


@pytree_dataclass
class Turbulence:
    """Dryden turbulence of one flight: severity code (0 none, 1 light, 2 moderate, 3 severe) for the
    high-altitude intensities, w20_mps the wind speed at 20 ft [m/s] for the low-altitude ones, and the
    key of the flight's own white noise."""

    severity: jnp.ndarray
    w20_mps: jnp.ndarray
    key: jax.Array

    @classmethod
    def from_severity(cls, severity, key, w20_mps=None) -> Turbulence:
        """W20 from the severity (15/30/45 kt) unless given."""
        severity = jnp.asarray(severity, dtype=float)
        if w20_mps is None:
            w20_mps = jnp.interp(severity, jnp.arange(len(SEVERITIES), dtype=float), jnp.asarray(SEVERITY_W20_MPS))
        return cls(severity, jnp.asarray(w20_mps, dtype=float), key)


@pytree_dataclass
class DrydenFilters:
    """Normalised (unit-variance) states of the u, v and w filters of one regime."""

    u: jnp.ndarray
    v1: jnp.ndarray
    v2: jnp.ndarray
    w1: jnp.ndarray
    w2: jnp.ndarray


@pytree_dataclass
class TurbulenceState:
    """The low- and high-altitude filters."""

    low: DrydenFilters
    high: DrydenFilters


class DrydenScales(NamedTuple):
    """Intensities σ [m/s] and scale lengths L [m] of the three components of one regime."""

    sigma_u: jnp.ndarray
    sigma_v: jnp.ndarray
    sigma_w: jnp.ndarray
    length_u: jnp.ndarray
    length_v: jnp.ndarray
    length_w: jnp.ndarray


def low_altitude_scales(w20_mps, height_m) -> DrydenScales:
    """MIL-F-8785C low-altitude model at ``height_m`` above ground, clamped to [10, 1000] ft:
    σ_w = 0.1·W20, σ_u = σ_v = σ_w/(0.177 + 0.000823 h)^0.4, L_w = h, L_u = L_v = h/(0.177 + 0.000823 h)^1.2
    (h in ft)."""
    h_ft = jnp.clip(height_m, LOW_ALTITUDE_FLOOR_M, LOW_ALTITUDE_TOP_M) / FT
    log_k = jnp.log(0.177 + 0.000823 * h_ft)
    sigma_w = 0.1 * w20_mps
    sigma_uv = sigma_w * jnp.exp(-0.4 * log_k)
    length_uv = h_ft * jnp.exp(-1.2 * log_k) * FT
    return DrydenScales(sigma_uv, sigma_uv, sigma_w, length_uv, length_uv, h_ft * FT)


def high_altitude_scales(severity, height_m) -> DrydenScales:
    """Medium/high-altitude model at ``height_m`` above ground (not below 2000 ft): isotropic, L = 1750 ft."""
    h = jnp.maximum(height_m, HIGH_ALTITUDE_BASE_M)
    sigma = interpolate(HIGH_ALTITUDE_SIGMA, (severity, h))[0][0]
    length = jnp.full_like(sigma, HIGH_ALTITUDE_SCALE_M)
    return DrydenScales(sigma, sigma, sigma, length, length, length)


def _first_order_step(z, s, n):
    """Exact step of the unit-variance OU state over s = h/τ with a standard normal n."""
    return jnp.exp(-s) * z + safe_sqrt(-jnp.expm1(-2.0 * s)) * n


def _second_order_step(z1, z2, s, n1, n2):
    """Exact step of the normalised repeated-pole pair over s = h/τ with standard normals n1, n2.

    Transition e^{−s}[[1, √2 s], [0, 1]]; stationary covariance [[1, 1/√2], [1/√2, 1]]; the noise
    covariance Q = P∞ − ΦP∞Φᵀ is drawn through its Cholesky factor (z2 first).
    """
    decay = jnp.exp(-s)
    one_minus_phi2 = -jnp.expm1(-2.0 * s)
    phi2 = decay * decay
    q22 = one_minus_phi2
    q12 = (one_minus_phi2 - 2.0 * s * phi2) / _SQRT2
    q11 = one_minus_phi2 - 2.0 * s * phi2 * (1.0 + s)
    l22 = safe_sqrt(q22)
    l21 = q12 / jnp.where(l22 > 0.0, l22, 1.0)
    l11 = safe_sqrt(jnp.maximum(q11 - l21 * l21, 0.0))
    return decay * (z1 + _SQRT2 * s * z2) + l21 * n2 + l11 * n1, decay * z2 + l22 * n2


def _advance_filters(f: DrydenFilters, scales: DrydenScales, distance_m, noise) -> DrydenFilters:
    """Step every filter over ``distance_m`` = V·h travelled through the frozen field."""
    n = noise
    u = _first_order_step(f.u, distance_m / scales.length_u, n[0])
    v1, v2 = _second_order_step(f.v1, f.v2, distance_m / scales.length_v, n[1], n[2])
    w1, w2 = _second_order_step(f.w1, f.w2, distance_m / scales.length_w, n[3], n[4])
    return DrydenFilters(u, v1, v2, w1, w2)


def _stationary_filters(n) -> DrydenFilters:
    """A draw from the filters' stationary distribution (unit variances, v1–v2 and w1–w2 correlation 1/√2)."""
    return DrydenFilters(n[0], (n[1] + n[2]) / _SQRT2, n[2], (n[3] + n[4]) / _SQRT2, n[4])


def _gust_components(f: DrydenFilters, scales: DrydenScales) -> Vec3:
    """(u, v, w) gust velocities [m/s] in the regime's axes."""
    return Vec3(
        scales.sigma_u * f.u,
        scales.sigma_v * (_V_MIX[0] * f.v1 + _V_MIX[1] * f.v2),
        scales.sigma_w * (_V_MIX[0] * f.w1 + _V_MIX[1] * f.w2),
    )


NOISE_PER_STEP = 10
"""Standard normals per step: 5 per regime (u, v1, v2, w1, w2)."""


def turbulence_noise(turbulence: Turbulence, block, n_steps: int):
    """The standard normals of ``n_steps`` steps, (n_steps, NOISE_PER_STEP), for block ``block`` of
    the flight's steps, from the flight's own key.

    Drawn a block at a time, outside the step loop: one draw of n_steps × 10 numbers costs a fraction
    of n_steps draws of 10 inside it (measured: JAX's threefry is a rolled loop on CPU, ~40 % of
    a step's XLA operations when drawn per step). The gusts therefore depend on the block length.
    Drawn in float32 (a white noise needs no more; ~4 % of lynx_nominal's throughput).
    """
    noise = jax.random.normal(jax.random.fold_in(turbulence.key, block + 1), (n_steps, NOISE_PER_STEP), jnp.float32)
    return noise.astype(jnp.result_type(float))


def initial_turbulence(turbulence: Turbulence) -> TurbulenceState:
    """Filters drawn from their stationary distribution, so the gusts are statistically steady from t = 0."""
    n = jax.random.normal(jax.random.fold_in(turbulence.key, 0), (NOISE_PER_STEP,))
    return TurbulenceState(_stationary_filters(n[:5]), _stationary_filters(n[5:]))


class RegimeScales(NamedTuple):
    """``DrydenScales`` of the low- and high-altitude regimes at one height, and the high regime's
    blend weight λ (0 below 1000 ft, 1 above 2000 ft)."""

    low: DrydenScales
    high: DrydenScales
    blend: jnp.ndarray


def turbulence_scales(turbulence: Turbulence, height_m) -> RegimeScales:
    """Intensities and scale lengths of both regimes at ``height_m`` above ground [m]."""
    blend = jnp.clip((height_m - LOW_ALTITUDE_TOP_M) / (HIGH_ALTITUDE_BASE_M - LOW_ALTITUDE_TOP_M), 0.0, 1.0)
    return RegimeScales(
        low_altitude_scales(turbulence.w20_mps, height_m), high_altitude_scales(turbulence.severity, height_m), blend
    )


def gust_n(state: TurbulenceState, scales: RegimeScales, mean_wind_n: Vec3, q_nb: Quat) -> Vec3:
    """Turbulent gust velocity [m/s, NED] to add to the mean wind, with the ``turbulence_scales`` of the
    height, the mean wind there (its direction sets the low-altitude axes) and the attitude."""
    low = _gust_components(state.low, scales.low)
    high = _gust_components(state.high, scales.high)
    speed = safe_sqrt(mean_wind_n.x**2 + mean_wind_n.y**2)
    calm = speed == 0.0
    c = jnp.where(calm, 1.0, mean_wind_n.x / jnp.where(calm, 1.0, speed))  # cos and sin of the heading the
    s = jnp.where(calm, 0.0, mean_wind_n.y / jnp.where(calm, 1.0, speed))  # mean wind blows toward (north if calm)
    low_n = Vec3(c * low.x - s * low.y, s * low.x + c * low.y, low.z)
    return low_n * safe_sqrt(1.0 - scales.blend) + q_nb.rotate(high) * safe_sqrt(scales.blend)


def advance_turbulence(state: TurbulenceState, scales: RegimeScales, speed_mps, dt_s, noise) -> TurbulenceState:
    """The filters ``dt_s`` later for a flight at airspeed ``speed_mps`` [m/s], the ``turbulence_scales``
    held at their values at the step's start; ``noise``: the step's row of ``turbulence_noise``."""
    distance = speed_mps * dt_s
    low = _advance_filters(state.low, scales.low, distance, noise[:5])
    high = _advance_filters(state.high, scales.high, distance, noise[5:])
    return TurbulenceState(low, high)

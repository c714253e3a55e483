"""International Standard Atmosphere (ISO 2533 / U.S. Standard Atmosphere 1976), 0–47 km, and the
day's atmosphere of a sounding or reanalysis profile (``AtmosphereProfile``).

Altitudes are geometric metres above mean sea level; the layer formulas use geopotential
altitude H = R0·z/(R0 + z). Above 47 km the state is held at the 47 km value (the caller flags
that as out of range).
"""

from __future__ import annotations

from typing import NamedTuple

import jax.numpy as jnp
import numpy as np

from ..math.interp import segment
from ..pytree import pytree_dataclass

G0 = 9.80665  # standard gravity [m/s²]
R_AIR = 287.05287  # specific gas constant of dry air [J/(kg·K)]
GAMMA_AIR = 1.4  # ratio of specific heats [-]
R_EARTH_GEOPOTENTIAL = 6356766.0  # radius used for geopotential altitude [m]
T0 = 288.15  # sea-level temperature [K]
P0 = 101325.0  # sea-level pressure [Pa]

# Layer bases (geopotential m) and temperature lapse rates (K/m): troposphere, tropopause,
# two stratosphere layers.
_BASE_H = (0.0, 11000.0, 20000.0, 32000.0)
_LAPSE = (-0.0065, 0.0, 0.001, 0.0028)
MAX_ALTITUDE_M = 47000.0 * R_EARTH_GEOPOTENTIAL / (R_EARTH_GEOPOTENTIAL - 47000.0)
MIN_ALTITUDE_M = -2000.0


def _layer_bases():
    """Base temperature [K] and pressure [Pa] of each layer, integrated once on the host."""
    temps, pressures = [T0], [P0]
    for i in range(1, len(_BASE_H)):
        dh, lapse, tb, pb = _BASE_H[i] - _BASE_H[i - 1], _LAPSE[i - 1], temps[-1], pressures[-1]
        if lapse == 0.0:
            pressures.append(pb * np.exp(-G0 * dh / (R_AIR * tb)))
            temps.append(tb)
        else:
            t_top = tb + lapse * dh
            pressures.append(pb * (t_top / tb) ** (-G0 / (R_AIR * lapse)))
            temps.append(t_top)
    return tuple(temps), tuple(pressures)


_BASE_T, _BASE_P = _layer_bases()


class AtmosphereState(NamedTuple):
    """Air at one altitude: temperature [K], pressure [Pa], density [kg/m³], speed of sound [m/s]."""

    temperature: jnp.ndarray
    pressure: jnp.ndarray
    density: jnp.ndarray
    speed_of_sound: jnp.ndarray


def geopotential_altitude(z):
    """Geopotential altitude [m] of the geometric altitude ``z`` [m]."""
    return R_EARTH_GEOPOTENTIAL * z / (R_EARTH_GEOPOTENTIAL + z)


def inverse_square_gravity(altitude_msl):
    """Gravity [m/s²] at a geometric altitude above mean sea level [m]: G0·(r0/(r0 + z))², r0 =
    ``R_EARTH_GEOPOTENTIAL``, the law the standard atmosphere's geopotential altitude rests on (US Standard
    Atmosphere 1976, eq. 17)."""
    return G0 * (R_EARTH_GEOPOTENTIAL / (R_EARTH_GEOPOTENTIAL + altitude_msl)) ** 2


def isa(altitude_msl) -> AtmosphereState:
    """ISA state at a geometric altitude above mean sea level [m], clamped to [-2, 47] km."""
    return _isa_at_geopotential(geopotential_altitude(jnp.clip(altitude_msl, MIN_ALTITUDE_M, MAX_ALTITUDE_M)))


def _isa_at_geopotential(h) -> AtmosphereState:
    """ISA state at a geopotential altitude ``h`` [m] inside its layers."""
    hb, tb, pb, lapse = _BASE_H[0], _BASE_T[0], _BASE_P[0], _LAPSE[0]
    for i in range(1, len(_BASE_H)):
        above = h >= _BASE_H[i]
        hb = jnp.where(above, _BASE_H[i], hb)
        tb = jnp.where(above, _BASE_T[i], tb)
        pb = jnp.where(above, _BASE_P[i], pb)
        lapse = jnp.where(above, _LAPSE[i], lapse)
    isothermal = lapse == 0.0
    temperature = tb + lapse * (h - hb)
    safe_lapse = jnp.where(isothermal, 1.0, lapse)
    pressure = jnp.where(
        isothermal,
        pb * jnp.exp(-G0 * (h - hb) / (R_AIR * tb)),
        pb * (temperature / tb) ** (-G0 / (R_AIR * safe_lapse)),
    )
    return _dry_air(temperature, pressure)


def _dry_air(temperature, pressure) -> AtmosphereState:
    """Dry air at ``temperature`` [K] and ``pressure`` [Pa]: density p/(R·T), speed of sound √(γ·R·T)."""
    density = pressure / (R_AIR * temperature)
    return AtmosphereState(temperature, pressure, density, jnp.sqrt(GAMMA_AIR * R_AIR * temperature))


ISOTHERMAL_RATIO = 1e-6
"""Below this |ln(T₁/T₀)| a profile segment is taken as isothermal (ln p linear in height): the polytrope's
pressure differs from that by ~|ln(T₁/T₀)|·|ln(p₁/p₀)|/8 < 1e-9 relative there, and the ratio of the two
logarithms would lose digits to rounding."""


@pytree_dataclass
class AtmosphereProfile:
    """The day's atmosphere at K levels (a sounding's or a reanalysis's, ``env.weather``).

    height_m (K,): geopotential altitude of each level [m], strictly increasing; temperature_k (K,) [K];
    log_pressure (K,): ln of the pressure [Pa]. Between two levels the temperature is linear in geopotential
    height and ln p linear in ln T: the hydrostatic polytrope of a layer with a constant lapse rate, its
    exponent fitted to both levels' pressures (ln p linear in height where the layer is isothermal), so each
    level's values are met exactly and the ISA sampled at levels inside one of its layers is the ISA again.
    Beyond the end levels the ISA's variation continues from the nearest one: T = T_end + T_ISA(H) − T_ISA(H_end),
    p = p_end·p_ISA(H)/p_ISA(H_end), clamped like ``isa`` to [-2, 47] km. Dry air (no humidity).
    """

    height_m: jnp.ndarray
    temperature_k: jnp.ndarray
    log_pressure: jnp.ndarray

    def state(self, altitude_msl) -> AtmosphereState:
        """The air at a geometric altitude above mean sea level [m]."""
        h = geopotential_altitude(jnp.clip(altitude_msl, MIN_ALTITUDE_M, MAX_ALTITUDE_M))
        i, s = segment(h, self.height_m)
        t0, t1 = self.temperature_k[i], self.temperature_k[i + 1]
        p0, p1 = self.log_pressure[i], self.log_pressure[i + 1]
        temperature = t0 + s * (t1 - t0)
        ratio = jnp.log(t1 / t0)
        isothermal = jnp.abs(ratio) < ISOTHERMAL_RATIO
        fraction = jnp.where(isothermal, s, jnp.log(temperature / t0) / jnp.where(isothermal, 1.0, ratio))
        log_pressure = p0 + fraction * (p1 - p0)
        outside, end = _isa_at_geopotential(h), _isa_at_geopotential(jnp.clip(h, self.height_m[0], self.height_m[-1]))
        temperature = temperature + (outside.temperature - end.temperature)  # exactly 0 between the end levels
        pressure = jnp.exp(log_pressure + (jnp.log(outside.pressure) - jnp.log(end.pressure)))
        return _dry_air(temperature, pressure)


def air(profile: AtmosphereProfile | None, altitude_msl) -> AtmosphereState:
    """The air at a geometric altitude above mean sea level [m]: the day's ``profile``, or the ISA without one."""
    return isa(altitude_msl) if profile is None else profile.state(altitude_msl)


def troposphere_altitude(pressure_pa):
    """Geometric altitude above mean sea level [m] where the ISA troposphere (below 11 km) has
    ``pressure_pa`` [Pa]: what a barometer calibrated to the standard atmosphere reads (host or traced)."""
    lapse = _LAPSE[0]
    geopotential = T0 / lapse * ((pressure_pa / P0) ** (-R_AIR * lapse / G0) - 1.0)
    return R_EARTH_GEOPOTENTIAL * geopotential / (R_EARTH_GEOPOTENTIAL - geopotential)


def pressure_height_m(pressure_pa, reference_pressure_pa):
    """Geometric height [m] of the ISA troposphere level at ``pressure_pa`` above the one at
    ``reference_pressure_pa`` [Pa] (a barometer's height above the pad whose pressure it read; host or traced)."""
    return troposphere_altitude(pressure_pa) - troposphere_altitude(reference_pressure_pa)

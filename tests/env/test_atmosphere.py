"""ISA against the published U.S. Standard Atmosphere 1976 / ICAO table (geopotential altitudes)."""

import numpy as np
import pytest

from rocketmc.env import isa
from rocketmc.env.atmosphere import R_EARTH_GEOPOTENTIAL
from rocketmc.env.wind import WindLayers, layered_wind

# H [m geopotential], T [K], p [Pa], rho [kg/m3]: U.S. Standard Atmosphere 1976, Table I.
TABLE = [
    (0.0, 288.150, 101325.0, 1.2250),
    (1000.0, 281.650, 89874.6, 1.1117),
    (3000.0, 268.650, 70108.5, 0.90912),
    (5000.0, 255.650, 54019.9, 0.73612),
    (11000.0, 216.650, 22632.1, 0.36392),
    (20000.0, 216.650, 5474.89, 0.088035),
    (32000.0, 228.650, 868.019, 0.013225),
]


@pytest.mark.parametrize(("h", "t", "p", "rho"), TABLE)
def test_isa_matches_table(h, t, p, rho):
    z = R_EARTH_GEOPOTENTIAL * h / (R_EARTH_GEOPOTENTIAL - h)  # geometric altitude
    air = isa(z)
    # Tolerances: the table prints 6 significant digits for T and p, 5 for rho; the pressure also
    # absorbs ~1e-6 from the gas constant (ISO 287.05287 vs US76 8314.32/28.9644 J/(kg K)).
    assert float(air.temperature) == pytest.approx(t, abs=1e-3)
    assert float(air.pressure) == pytest.approx(p, rel=5e-6)
    assert float(air.density) == pytest.approx(rho, rel=1e-4)


def test_speed_of_sound_sea_level():
    assert float(isa(0.0).speed_of_sound) == pytest.approx(340.294, abs=1e-3)  # table value


def test_clamped_outside_range():
    for z in (-5000.0, 60000.0, 1e6):
        air = isa(z)
        assert all(np.isfinite(float(x)) for x in air)


def test_layered_wind_layers_and_direction():
    layers = WindLayers.from_speed_direction(
        np.array([0.0, 100.0, 400.0]), np.array([5.0, 10.0, 20.0]), np.deg2rad([180.0, 270.0, 0.0])
    )
    w = layered_wind(layers, 50.0)  # from the south: blows toward north
    assert float(w.x) == pytest.approx(5.0) and abs(float(w.y)) < 1e-12
    w = layered_wind(layers, 100.0)  # from the west: blows toward east (boundary belongs to the upper layer)
    assert float(w.y) == pytest.approx(10.0) and abs(float(w.x)) < 1e-12
    w = layered_wind(layers, 5000.0)  # from the north: toward south
    assert float(w.x) == pytest.approx(-20.0)
    assert float(layered_wind(layers, -3.0).x) == pytest.approx(5.0)

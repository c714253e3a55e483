"""Mean wind models: layer selection, the meteorological direction convention, measured profiles, power law."""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from rocketmc.env import PowerLawWind, WindLayers, WindProfile
from rocketmc.env.wind import read_wind_profile

BOTTOMS = np.array([0.0, 275.0, 450.0])


def layers_from(speeds, from_deg):
    return WindLayers.from_speed_direction(jnp.asarray(BOTTOMS), jnp.asarray(speeds), jnp.deg2rad(jnp.asarray(from_deg)))


# cos/sin of a multiple of 90° in radians leave ~1e-16 residues: 1e-12 m/s absolute.
ATOL = 1e-12


@pytest.mark.parametrize(
    ("from_deg", "north", "east"),
    [
        (180.0, 1.0, 0.0),  # from the south: blows toward the north
        (0.0, -1.0, 0.0),  # from the north: toward the south
        (270.0, 0.0, 1.0),  # from the west: toward the east
        (90.0, 0.0, -1.0),  # from the east: toward the west
        (225.0, np.sqrt(0.5), np.sqrt(0.5)),  # from the south-west: toward the north-east
    ],
)
def test_direction_convention(from_deg, north, east):
    speed = 12.0
    w = layers_from([speed] * 3, [from_deg] * 3).velocity_n(100.0)
    assert float(w.x) == pytest.approx(speed * north, abs=ATOL)
    assert float(w.y) == pytest.approx(speed * east, abs=ATOL)
    assert float(w.z) == 0.0  # horizontal only


@pytest.mark.parametrize(
    ("altitude", "layer"),
    [
        (-50.0, 0),  # below ground: the first layer
        (0.0, 0),
        (274.999, 0),
        (275.0, 1),  # a boundary belongs to the layer above it
        (449.999, 1),
        (450.0, 2),
        (12000.0, 2),  # the top layer extends without limit
    ],
)
def test_picks_the_layer(altitude, layer):
    speeds, dirs = [7.5, 15.0, 10.0], [180.0, 270.0, 45.0]
    w = layers_from(speeds, dirs).velocity_n(altitude)
    d = np.deg2rad(dirs[layer])
    np.testing.assert_allclose([float(w.x), float(w.y)], [-speeds[layer] * np.cos(d), -speeds[layer] * np.sin(d)], atol=ATOL)
    assert float(jnp.hypot(w.x, w.y)) == pytest.approx(speeds[layer], rel=1e-15)


def test_vmap_over_altitudes_and_over_layer_sets():
    layers = layers_from([7.5, 15.0, 10.0], [180.0, 200.0, 220.0])
    alt = jnp.linspace(-10.0, 600.0, 62)
    w = jax.jit(jax.vmap(WindLayers.velocity_n, in_axes=(None, 0)))(layers, alt)
    expected_layer = np.searchsorted(BOTTOMS, np.asarray(alt), side="right") - 1
    expected_layer = np.clip(expected_layer, 0, 2)
    np.testing.assert_array_equal(np.asarray(w.x), np.asarray(layers.north_mps)[expected_layer])  # selection: exact
    np.testing.assert_array_equal(np.asarray(w.y), np.asarray(layers.east_mps)[expected_layer])
    # a batch of dispersed wind profiles (as in a campaign): vmap over the layers themselves
    speeds = jnp.array([[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]])
    batch = jax.vmap(lambda s: WindLayers.from_speed_direction(jnp.asarray(BOTTOMS), s, jnp.full(3, jnp.pi)))(speeds)
    w = jax.vmap(WindLayers.velocity_n, in_axes=(0, None))(batch, 300.0)
    np.testing.assert_allclose(np.asarray(w.x), [2.0, 5.0], rtol=1e-15)  # from the south, layer 1


def test_profile_interpolates_components_and_holds_its_ends(tmp_path):
    path = tmp_path / "sounding.csv"
    path.write_text("# a radiosonde, heights above sea level\naltitude_msl_m,speed_mps,from_deg\n"
                    "1416,4.0,270\n1916,8.0,180\n3416,20.0,180\n")  # fmt: skip
    altitude, speed, from_rad = read_wind_profile(path, site_altitude_m=1416.0)
    np.testing.assert_array_equal(altitude, [0.0, 500.0, 2000.0])
    profile = WindProfile.from_speed_direction(altitude, speed, from_rad)
    # halfway between (east 4, north 0) and (north 8, east 0): each component linear, to ATOL
    w = profile.velocity_n(250.0)
    assert (float(w.x), float(w.y)) == pytest.approx((4.0, 2.0), abs=ATOL)
    assert float(profile.velocity_n(-10.0).y) == pytest.approx(4.0, abs=ATOL)  # below: the first row
    assert float(profile.velocity_n(9000.0).x) == pytest.approx(20.0, abs=ATOL)  # above: the last row
    assert profile.jump_altitudes_m() == []


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("height,speed_mps,from_deg\n0,1,0\n10,2,0\n", "expected columns"),
        ("altitude_agl_m,speed_mps,from_deg\n0,1,0\n", "at least 2 rows"),
        ("altitude_agl_m,speed_mps,from_deg\n0,1,0\n0,2,0\n", "strictly increasing"),
        ("altitude_agl_m,speed_mps,from_deg\n0,1,0\n10,fast,0\n", "numbers"),
        ("altitude_agl_m,speed_mps,from_deg\n0,1,0\n10,-2,0\n", "negative"),
    ],
)
def test_profile_file_errors_name_the_problem(tmp_path, text, message):
    path = tmp_path / "bad.csv"
    path.write_text(text)
    with pytest.raises(ValueError, match=message):
        read_wind_profile(path, 0.0)


def test_power_law_against_its_formula():
    wind = PowerLawWind(jnp.asarray(6.0), jnp.asarray(10.0), jnp.asarray(1.0 / 7.0), jnp.deg2rad(jnp.asarray(270.0)))
    for h in (10.0, 80.0, 1500.0):
        w = wind.velocity_n(h)
        assert float(w.y) == pytest.approx(6.0 * (h / 10.0) ** (1.0 / 7.0), rel=1e-14)  # from the west: east
        assert float(w.x) == pytest.approx(0.0, abs=ATOL)
    # held below 1 m (the law is singular at the ground)
    assert float(wind.velocity_n(0.0).y) == float(wind.velocity_n(1.0).y)

"""Layered wind: layer selection and the meteorological direction convention."""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from rocketmc.env import WindLayers, layered_wind

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
    w = layered_wind(layers_from([speed] * 3, [from_deg] * 3), 100.0)
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
    w = layered_wind(layers_from(speeds, dirs), altitude)
    d = np.deg2rad(dirs[layer])
    np.testing.assert_allclose([float(w.x), float(w.y)], [-speeds[layer] * np.cos(d), -speeds[layer] * np.sin(d)], atol=ATOL)
    assert float(jnp.hypot(w.x, w.y)) == pytest.approx(speeds[layer], rel=1e-15)


def test_vmap_over_altitudes_and_over_layer_sets():
    layers = layers_from([7.5, 15.0, 10.0], [180.0, 200.0, 220.0])
    alt = jnp.linspace(-10.0, 600.0, 62)
    w = jax.jit(jax.vmap(layered_wind, in_axes=(None, 0)))(layers, alt)
    expected_layer = np.searchsorted(BOTTOMS, np.asarray(alt), side="right") - 1
    expected_layer = np.clip(expected_layer, 0, 2)
    np.testing.assert_array_equal(np.asarray(w.x), np.asarray(layers.north_mps)[expected_layer])  # selection: exact
    np.testing.assert_array_equal(np.asarray(w.y), np.asarray(layers.east_mps)[expected_layer])
    # a batch of dispersed wind profiles (as in a campaign): vmap over the layers themselves
    speeds = jnp.array([[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]])
    batch = jax.vmap(lambda s: WindLayers.from_speed_direction(jnp.asarray(BOTTOMS), s, jnp.full(3, jnp.pi)))(speeds)
    w = jax.vmap(layered_wind, in_axes=(0, None))(batch, 300.0)
    np.testing.assert_allclose(np.asarray(w.x), [2.0, 5.0], rtol=1e-15)  # from the south, layer 1

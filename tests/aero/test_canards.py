"""Canard mixing against the thesis's matrix (docs/lynx.md), written out independently with numpy."""

import numpy as np

from rocketmc.aero.canards import allocate, mix

THESIS_MIXING = np.array(  # rows: yaw, pitch, roll, squeeze; columns: delta 1..4 (docs/lynx.md)
    [[-0.5, 0, 0.5, 0], [0, 0.5, 0, -0.5], [-0.25, -0.25, -0.25, -0.25], [-0.25, 0.25, -0.25, 0.25]]
)


def test_mix_is_the_thesis_matrix():
    rng = np.random.default_rng(0)
    for delta in rng.normal(size=(20, 4)):
        np.testing.assert_allclose(mix(*delta), THESIS_MIXING @ delta, rtol=0, atol=1e-15)  # exact up to rounding


def test_allocate_is_the_inverse():
    np.testing.assert_allclose(
        np.array([allocate(*col) for col in np.eye(4)]).T, np.linalg.inv(THESIS_MIXING), atol=1e-15
    )
    u = (0.01, -0.02, 0.005, 0.0)
    np.testing.assert_allclose(mix(*allocate(*u)), u, atol=1e-16)

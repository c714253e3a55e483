"""The L1350 motor: impulse, propellant and grain inertia against independent references."""

from importlib import resources
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from scipy.integrate import trapezoid

from rocketmc.dynamics import Motor, propellant_mass, read_thrust_curve, thrust
from rocketmc.dynamics.propulsion import ThrustCurveError, cumulative_impulse, delivered_impulse, grain_inertia

ENG = Path(str(resources.files("rocketmc") / "data" / "motors" / "Cesaroni_4263L1350-P.eng"))
T, F = read_thrust_curve(ENG)
M0, D_OUT, D_IN, LENGTH = 1.905, 0.075, 0.020, 0.532
MOTOR = Motor(
    time_s=jnp.asarray(T), thrust_n=jnp.asarray(F), impulse_ns=jnp.asarray(cumulative_impulse(T, F)),
    ignition_time_s=jnp.asarray(0.5), propellant_mass_kg=jnp.asarray(M0), grain_outer_diameter_m=jnp.asarray(D_OUT),
    grain_inner_diameter_m=jnp.asarray(D_IN), grain_length_m=jnp.asarray(LENGTH), grain_center_x_m=jnp.asarray(-0.884),
    nozzle_x_m=jnp.asarray(-1.15),
)  # fmt: skip


def test_total_impulse():
    total = float(delivered_impulse(MOTOR, 10.0))
    assert total == pytest.approx(trapezoid(F, T), rel=1e-12)  # same integral, rounding only
    assert total == pytest.approx(4263.0, rel=0.01)  # certified 4263 N·s; the file's points are rounded


def test_burns_exactly_its_propellant():
    t = np.linspace(0.0, 5.0, 2001)
    m = np.asarray(jax.vmap(lambda x: propellant_mass(MOTOR, x))(t))
    assert m[0] == pytest.approx(M0, abs=1e-15) and abs(m[-1]) < 1e-12
    assert np.all(np.diff(m) <= 1e-15)  # never grows
    # Mass flow = thrust · m0 / I_tot, by central differences (error O(dt²·F''), tiny for a piecewise-linear curve).
    dt = 1e-6
    for tc in (0.7, 1.3, 2.0, 3.0):
        flow = -(float(propellant_mass(MOTOR, tc + dt)) - float(propellant_mass(MOTOR, tc - dt))) / (2 * dt)
        expected = float(thrust(MOTOR, tc)) * M0 / trapezoid(F, T)
        assert flow == pytest.approx(expected, rel=1e-6)


def test_ignition_delay_and_burnout():
    assert float(thrust(MOTOR, 0.49)) == 0.0 and float(thrust(MOTOR, 0.5 + 3.3)) == 0.0
    assert float(thrust(MOTOR, 0.5 + 1.28)) == pytest.approx(1540.732)  # a curve point


def test_grain_inertia_hollow_cylinder():
    ixx, iyy = grain_inertia(MOTOR, M0)
    r_o, r_i = D_OUT / 2, D_IN / 2
    assert float(ixx) == pytest.approx(0.5 * M0 * (r_o**2 + r_i**2), rel=1e-12)
    assert float(iyy) == pytest.approx(M0 / 12 * (3 * (r_o**2 + r_i**2) + LENGTH**2), rel=1e-12)
    # Nearly burnt: a thin shell at the outer radius, I_xx -> m r_o².
    m = 1e-6
    ixx, _ = grain_inertia(MOTOR, m)
    assert float(ixx) == pytest.approx(m * r_o**2, rel=1e-6)


@pytest.mark.parametrize("text", ["", "; only a comment\n", "L1 75 486 P 2 3 CTI\n0.1 abc\n", "X 1 1 P 1 1 C\n0.2 5\n0.1 3\n"])
def test_bad_thrust_files(tmp_path, text):
    path = tmp_path / "bad.eng"
    path.write_text(text)
    with pytest.raises(ThrustCurveError):
        read_thrust_curve(path)
    with pytest.raises(ThrustCurveError, match="not found"):
        read_thrust_curve(tmp_path / "missing.eng")

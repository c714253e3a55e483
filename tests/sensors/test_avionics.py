"""The sensors in the flight (sensors/avionics.py through sim.flight): at rest on the pad their truth against
closed forms (gravity along the rail, the site's dipole field, the standard atmosphere), the GNSS schedule and
its sinusoidal bias against their formulas, the accelerometer's lever-arm terms, and the drawn errors."""

from __future__ import annotations

import dataclasses
import math
import tomllib

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from rocketmc.campaign import campaign_from_dict
from rocketmc.campaign.runner import realization_params, sim_settings
from rocketmc.env.atmosphere import G0
from rocketmc.env.magnetic import site_field_ned
from rocketmc.math import Quat, Vec3
from rocketmc.sensors.avionics import specific_force_b
from rocketmc.sim.events import rail_start_n
from rocketmc.sim.flight import fly

from ..conftest import CAMPAIGNS

RAW = tomllib.loads((CAMPAIGNS / "lynx_nominal.toml").read_text())
DT = 0.02


def static_bus(avionics: dict, seconds: float, realization: int = 0):
    """The bus after each period (and the flight parameters) of lynx_nominal with ``avionics``, at rest on the
    rail for ``seconds`` (its motor never lit)."""
    campaign = campaign_from_dict({**RAW, "avionics": avionics}, CAMPAIGNS)
    p, _ = realization_params(campaign, jax.random.key(campaign.config.seed), np.uint32(realization))
    motor = dataclasses.replace(p.rocket.motor, ignition_time_s=jnp.asarray(jnp.inf))
    p = dataclasses.replace(p, rocket=dataclasses.replace(p.rocket, motor=motor))
    n = round(seconds / DT)
    _, bus = jax.jit(lambda p: fly(p, sim_settings(campaign), n, record=lambda s: s.avionics.bus))(p)
    return campaign, p, jax.tree_util.tree_map(np.asarray, bus)


@pytest.fixture(scope="module")
def at_rest():
    return static_bus({"truth_only": True}, 1.0)


def test_at_rest_the_accelerometer_reads_gravity_along_the_rail(at_rest):
    _, p, bus = at_rest
    f = bus.accelerometer.value
    sin_elevation = -float(p.launch.rail_direction_n.z)  # the drawn elevation's (NED: the rail points up)
    # at rest the specific force is −g: |f| = g, and its component along the body x axis (the rail) g·sin(elevation)
    np.testing.assert_allclose(np.linalg.norm(f, axis=1), G0, rtol=1e-14)
    np.testing.assert_allclose(f[:, 0], G0 * sin_elevation, rtol=1e-14)


def test_at_rest_the_gyro_reads_zero_and_the_magnetometer_the_site_dipole(at_rest):
    campaign, _, bus = at_rest
    site = campaign.config.site
    field = site_field_ned(site.latitude_deg, site.longitude_deg, site.altitude_m) * 1e-9  # [T]
    np.testing.assert_array_equal(bus.gyroscope.value, 0.0)
    b, f = bus.magnetometer.value, bus.accelerometer.value
    # rotations keep the field's length, and its component along "up" (−f/g at rest): −B_down
    np.testing.assert_allclose(np.linalg.norm(b, axis=1), np.linalg.norm(field), rtol=1e-13)
    np.testing.assert_allclose(np.sum(b * f, axis=1) / G0, -field[2], rtol=1e-12)


def test_at_rest_the_barometer_reads_the_standard_atmosphere_at_its_height(at_rest):
    campaign, p, bus = at_rest
    # ISA troposphere written out here: p0 (T/T0)^(−g0/(R L)), T = T0 + L·h at the geopotential height h
    z = campaign.config.site.altitude_m - float(rail_start_n(p).z)  # the CG on the rail, above sea level
    h = 6_356_766.0 * z / (6_356_766.0 + z)
    expected = 101_325.0 * ((288.15 - 0.0065 * h) / 288.15) ** (9.80665 / (287.05287 * 0.0065))
    np.testing.assert_allclose(bus.barometer.value[:, 0], expected, rtol=1e-12)


def test_gnss_fixes_at_its_rate_from_its_first_fix_with_the_sinusoidal_bias():
    gnss = {"part": "thesis", "rate_hz": 25.0, "first_fix_s": 0.5, "position_noise_m": [0.0] * 3,
            "velocity_noise_mps": [0.0] * 3}  # fmt: skip
    campaign, p, bus = static_bus({"gnss": gnss}, 2.0)
    fresh = np.nonzero(bus.gnss.fresh)[0]
    # every second tick (25 Hz of 50), from the first tick at or after 0.5 s: ticks 26, 28, ... (t = tick·dt)
    np.testing.assert_array_equal(fresh, np.arange(26, 100, 2))  # row k: the bus after period k, tick k's samples
    assert not bus.gnss.valid[: fresh[0]].any() and bus.gnss.valid[fresh[0] :].all()
    config = campaign.config.avionics.gnss
    a, f = np.array(config.sinusoid_amplitude_m), config.sinusoid_frequency_hz
    phase = np.radians(config.sinusoid_phase_deg)
    t = fresh * DT  # each fix's tick time
    expected_r = np.array(rail_start_n(p))[None] + a * np.sin(2 * np.pi * f * t[:, None] + phase)
    expected_v = a * 2 * np.pi * f * np.cos(2 * np.pi * f * t[:, None] + phase)
    # the bias at the fix's time: only the rounding of sin/cos and of tick·dt (1e-12 of the 5-10 m amplitude)
    np.testing.assert_allclose(bus.gnss.value[fresh, :3], expected_r, rtol=0, atol=1e-12)
    np.testing.assert_allclose(bus.gnss.value[fresh, 3:], expected_v, rtol=0, atol=1e-12)


def test_the_accelerometer_sees_the_lever_arm_terms():
    # spinning at ω about z with angular acceleration α, a sensor at r = (x, y, 0) from the CG reads the
    # centripetal −ω²r and the tangential α×r on top of the CG's specific force (here −g rotated, level attitude)
    omega, alpha, x, y = 3.0, 2.0, 0.4, -0.1
    f = specific_force_b(Vec3(0.0, 0.0, 0.0), Quat(1.0, 0.0, 0.0, 0.0), Vec3(0.0, 0.0, omega), Vec3(0.0, 0.0, alpha),
                         Vec3(x, y, 0.0))  # fmt: skip
    np.testing.assert_allclose(f.to_array(), [-omega**2 * x - alpha * y, -omega**2 * y + alpha * x, -G0], rtol=1e-15)


def test_the_drawn_errors_are_the_parts_and_stay_put():
    # BMX160 gyro, uncalibrated: turn-on bias ~ N(0, 3 deg/s) per axis, drawn per flight; noise 0.007 deg/s/√Hz at 50 Hz
    parts = {"part": "bmx160_uncalibrated", "barometer": {"part": "ms5803_01ba_uncalibrated"}, "gnss": {"part": "neo_m9n"}}
    campaign, _, bus = static_bus(parts, 20.0, realization=3)
    drawn = realization_params(campaign, jax.random.key(campaign.config.seed), np.uint32(3))[1]
    bias = np.radians([float(drawn[f"avionics.gyroscope.bias.{i}"]) for i in range(3)])
    gyro = bus.gyroscope.value
    sigma = math.radians(0.007 * math.sqrt(50.0))
    # the mean of 1000 samples: the bias within 4 standard errors (σ/√1000), quantisation at 1/16.4 deg/s included
    lsb = math.radians(1 / 16.4)
    np.testing.assert_allclose(gyro.mean(axis=0), bias, rtol=0, atol=4 * math.hypot(sigma, lsb / math.sqrt(12)) / math.sqrt(1000))
    assert np.all(np.abs(np.diff(gyro, axis=0)) < 12 * sigma)  # white noise about the bias, no jumps


def test_a_static_record_has_the_configured_white_noise_level():
    # 20 minutes at rest (60 000 samples): the Allan deviation's white-noise level at τ = 1 s has ~1 800 equivalent
    # degrees of freedom there (±2.4 % at one σ), so 10 % is 4σ; the 2-hour records of the acceptance, with the
    # random walk's level, are docs/scripts/sensor_allan.py's (docs/validation.md).
    from rocketmc.analysis.allan import allan_deviation, noise_terms
    from rocketmc.campaign.sensor_record import sensor_record

    campaign = campaign_from_dict({**RAW, "avionics": {"part": "thesis"}}, CAMPAIGNS)
    imu = sensor_record(campaign, 0, static_s=1200.0)["imu"]
    for column, noise_std in (("acc_x_mps2", 0.1), ("gyro_x_radps", math.radians(0.3))):
        fit = noise_terms(*allan_deviation(imu[column].to_numpy(), 50.0))
        assert fit["N"] == pytest.approx(noise_std / math.sqrt(50.0), rel=0.1), column
        assert fit["white_slope"] == pytest.approx(-0.5, abs=0.05), column


def test_sensors_simulate_writes_the_real_logs_files_or_refuses_in_one_line(tmp_path, capsys):
    from rocketmc.analysis.sensor_log import LOG_FILES
    from rocketmc.cli import main

    out = tmp_path / "log"
    assert main(["sensors", "simulate", str(CAMPAIGNS / "lynx_nominal.toml"), "--out", str(out)]) == 2
    lines = capsys.readouterr().err.splitlines()
    assert len(lines) == 1 and "avionics: the campaign has no [avionics] section" in lines[0], lines
    assert not out.exists()
    campaign = tmp_path / "with_sensors.toml"
    campaign.write_text((CAMPAIGNS / "lynx_nominal.toml").read_text() + '\n[avionics]\npart = "bmx160"\n')
    assert main(["sensors", "simulate", str(campaign), "--static", "1", "--out", str(out), "--quiet"]) == 0
    assert capsys.readouterr().err == ""  # --quiet: errors only
    # the real log's files and columns; a second at 50 Hz, no GNSS fix yet (the thesis's first comes at 10 s)
    for stream, (file, header) in LOG_FILES.items():
        lines = (out / file).read_text().splitlines()
        assert lines[0] == ",".join(header) and len(lines) == 1 + {"gnss": 0}.get(stream, 50), file

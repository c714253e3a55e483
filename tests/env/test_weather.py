"""The day's atmosphere: the readers against the raw files read here independently, the profile's
interpolation against the ISA, the flight in an ISA-equal profile against the ISA flight, a weather campaign
end to end, and bad weather input refused in one line."""

import dataclasses
import math
import tomllib
from datetime import datetime, timezone
from pathlib import Path

import h5py
import jax
import jax.numpy as jnp
import numpy as np
import pytest
import scipy.io

from rocketmc.campaign import load_campaign
from rocketmc.campaign.model import nominal_params
from rocketmc.campaign.runner import sim_settings
from rocketmc.cli import main
from rocketmc.env.atmosphere import AtmosphereProfile, isa
from rocketmc.env.weather import read_weather
from rocketmc.sim.flight import simulate_one

ROOT = Path(__file__).parents[2]
WEATHER = ROOT / "src" / "rocketmc" / "data" / "weather"
ERA5_NC3, ERA5_NC4 = WEATHER / "euroc_2023_all_windows.nc", WEATHER / "euroc_2025_era5_pressure_levels.nc"
SOUNDING = WEATHER / "euroc_2023-10-13_12z_era5_uwyo.txt"
SITE = (39.3903, -8.2892)
G0 = 9.80665  # the geopotential's standard gravity [m/s²]
KNOT = 0.514444  # [m/s]


def direction_from_deg(u, v):
    """The meteorological direction, the textbook way: 270° − atan2(v, u), in [0, 360)."""
    return (270.0 - math.degrees(math.atan2(v, u))) % 360.0


def level_index(weather, pressure_pa):
    return int(np.flatnonzero(weather.pressure_pa == pressure_pa)[0])


# ------------------------------------------------------------------------------------------------ readers


def test_netcdf3_nearest_point_against_the_raw_arrays():
    with scipy.io.netcdf_file(ERA5_NC3, "r", mmap=False) as f:
        var = {k: f.variables[k] for k in ("z", "t", "u", "v")}
        unpack = {k: v[...].astype(float) * v.scale_factor + v.add_offset for k, v in var.items()}
        hours = f.variables["time"][:].astype(float)
        levels = f.variables["level"][:]
    # 2023-10-13 12:00 in hours after 1900-01-01, from the calendar
    want = (datetime(2023, 10, 13, 12) - datetime(1900, 1, 1)).total_seconds() / 3600.0
    it, ik = int(np.flatnonzero(hours == want)[0]), int(np.flatnonzero(levels == 850)[0])
    ilat, ilon = 2, 3  # 39.50 N is 0.110° from the pad, 39.25 N 0.140°; −8.25 E is 0.039° away
    z, t, u, v = (unpack[k][it, ik, ilat, ilon] for k in ("z", "t", "u", "v"))

    w = read_weather(ERA5_NC3, *SITE, datetime(2023, 10, 13, 12, 20, tzinfo=timezone.utc), "nearest")
    k = level_index(w, 85_000.0)
    assert w.time_utc == datetime(2023, 10, 13, 12, tzinfo=timezone.utc)  # the nearest hour
    # exact to rounding: the same unpacking, in another order of operations
    np.testing.assert_allclose(w.geopotential_height_m[k], z / G0, rtol=1e-12)
    np.testing.assert_allclose(w.temperature_k[k], t, rtol=1e-12)
    np.testing.assert_allclose(w.speed_mps[k], math.hypot(u, v), rtol=1e-12)
    np.testing.assert_allclose(math.degrees(w.from_rad[k]), direction_from_deg(u, v), atol=1e-9)
    assert 1400.0 < w.geopotential_height_m[k] < 1700.0  # 850 hPa's usual height: the units are right
    assert len(w.pressure_pa) == 37 and np.all(np.diff(w.geopotential_height_m) > 0)


def test_netcdf4_bilinear_against_the_raw_arrays():
    with h5py.File(ERA5_NC4) as f:
        lat, lon, times = f["latitude"][:], f["longitude"][:], f["valid_time"][:]
        levels = f["pressure_level"][:]
        it = int(np.flatnonzero(times == datetime(2025, 10, 12, 17, tzinfo=timezone.utc).timestamp())[0])
        ik = int(np.flatnonzero(levels == 700.0)[0])
        corners = {k: f[k][it, ik].astype(float) for k in ("z", "t", "u", "v")}
    i0, j0 = int(np.flatnonzero(lat == 39.5)[0]), int(np.flatnonzero(lon == -8.5)[0])  # 39.5 > 39.3903 > 39.25
    a = (SITE[0] - lat[i0]) / (lat[i0 + 1] - lat[i0])  # latitude decreases along its axis
    b = (SITE[1] - lon[j0]) / (lon[j0 + 1] - lon[j0])

    def bilinear(x):
        return ((1 - a) * (1 - b) * x[i0, j0] + (1 - a) * b * x[i0, j0 + 1] + a * (1 - b) * x[i0 + 1, j0]
                + a * b * x[i0 + 1, j0 + 1])  # fmt: skip

    z, t, u, v = (bilinear(corners[k]) for k in ("z", "t", "u", "v"))
    w = read_weather(ERA5_NC4, *SITE, datetime(2025, 10, 12, 17, tzinfo=timezone.utc))
    k = level_index(w, 70_000.0)
    np.testing.assert_allclose(w.geopotential_height_m[k], z / G0, rtol=1e-12)
    np.testing.assert_allclose(w.temperature_k[k], t, rtol=1e-12)
    np.testing.assert_allclose(w.speed_mps[k], math.hypot(u, v), rtol=1e-12)
    np.testing.assert_allclose(math.degrees(w.from_rad[k]), direction_from_deg(u, v), atol=1e-9)


def test_uwyo_sounding_against_its_text():
    line = next(x for x in SOUNDING.read_text().splitlines() if x.startswith("  850.0"))
    pres, hght, temp, drct, sknt, _ = map(float, line.split())  # DWPT, RELH, MIXR are blank here
    w = read_weather(SOUNDING, *SITE)
    k = level_index(w, pres * 100.0)
    assert (w.geopotential_height_m[k], w.temperature_k[k]) == (hght, pytest.approx(temp + 273.15, abs=1e-12))
    assert w.speed_mps[k] == pytest.approx(sknt * KNOT, rel=1e-6)  # 1 kt = 1852/3600 m/s = 0.5144444
    assert math.degrees(w.from_rad[k]) == pytest.approx(drct, abs=1e-12)
    assert w.time_utc is None and len(w.pressure_pa) == 27


def test_csv_sounding_and_skipped_uwyo_levels(tmp_path):
    csv = tmp_path / "s.csv"
    csv.write_text("# synthetic\naltitude_msl_m,pressure_pa,temperature_k,speed_mps,from_deg\n"
                   "100,100000,290,3,90\n3000,70000,275,10,270\n")  # fmt: skip
    w = read_weather(csv, *SITE)
    r = 6356766.0
    np.testing.assert_allclose(w.geopotential_height_m, [r * 100 / (r + 100), r * 3000 / (r + 3000)], rtol=1e-15)
    np.testing.assert_allclose(np.degrees(w.from_rad), [90.0, 270.0])
    text = SOUNDING.read_text().replace("  975.0    387   20.9", "  975.0    387       ")  # TEMP missing: skipped
    (tmp_path / "u.txt").write_text(text)
    assert len(read_weather(tmp_path / "u.txt", *SITE).pressure_pa) == 26


# ------------------------------------------------------------------------------------------------ profile


def isa_profile(heights_m) -> AtmosphereProfile:
    """The ISA sampled at geopotential heights [m]."""
    h = np.asarray(heights_m, dtype=float)
    z = 6356766.0 * h / (6356766.0 - h)
    air = isa(jnp.asarray(z))
    return AtmosphereProfile(jnp.asarray(h), air.temperature, jnp.log(air.pressure))


def test_profile_of_isa_levels_is_the_isa_between_and_beyond_them():
    """Inside one ISA layer, T linear in H and ln p linear in ln T is the ISA's own law; beyond the end levels the
    ISA's variation continues: the ISA everywhere, to rounding (1e-12 relative, float64 logs and powers)."""
    profile = isa_profile([0.0, 800.0, 2500.0, 6000.0, 11000.0, 15000.0])
    z = jnp.linspace(-1500.0, 30000.0, 2001)
    got, want = profile.state(z), isa(z)
    for name in ("temperature", "pressure", "density", "speed_of_sound"):
        np.testing.assert_allclose(getattr(got, name), getattr(want, name), rtol=1e-12, err_msg=name)


def test_profile_meets_its_levels_and_continues_with_the_isa_lapse():
    h = np.array([0.0, 1000.0, 3000.0])
    t = np.array([300.0, 300.0, 280.0])  # an isothermal first layer
    p = np.array([100000.0, 89000.0, 70000.0])
    profile = AtmosphereProfile(jnp.asarray(h), jnp.asarray(t), jnp.log(jnp.asarray(p)))
    z = 6356766.0 * h / (6356766.0 - h)
    at = profile.state(jnp.asarray(z))
    np.testing.assert_allclose(at.temperature, t, rtol=1e-14)
    np.testing.assert_allclose(at.pressure, p, rtol=1e-14)
    mid = profile.state(jnp.asarray(6356766.0 * 500.0 / (6356766.0 - 500.0)))
    np.testing.assert_allclose(mid.pressure, math.sqrt(p[0] * p[1]), rtol=1e-12)  # isothermal: log-linear
    # inside the lapse layer: ln p linear in ln T, by hand at H = 2000 m
    t_mid = 290.0
    p_mid = p[1] * math.exp(math.log(p[2] / p[1]) * math.log(t_mid / t[1]) / math.log(t[2] / t[1]))
    at = profile.state(jnp.asarray(6356766.0 * 2000.0 / (6356766.0 - 2000.0)))
    np.testing.assert_allclose([at.temperature, at.pressure], [t_mid, p_mid], rtol=1e-12)
    # 2 km above the top level, inside the ISA troposphere: the ISA's -6.5 K/km and its pressure ratio
    z_top, z_above = (6356766.0 * hh / (6356766.0 - hh) for hh in (3000.0, 5000.0))
    above = profile.state(jnp.asarray(z_above))
    np.testing.assert_allclose(above.temperature, 280.0 - 13.0, rtol=1e-12)
    np.testing.assert_allclose(above.pressure, p[2] * isa(z_above).pressure / isa(z_top).pressure, rtol=1e-12)


# ------------------------------------------------------------------------------------------------ flights


def test_a_flight_in_an_isa_equal_profile_is_the_isa_flight(lynx_campaign, lynx_params):
    """The nominal Lynx (Roccaraso, layered wind) in the ISA and in a profile of ISA levels (apogee ~1.6 km above a
    1.3 km pad, inside the troposphere's one layer): apogee and impact agree to 1e-9 relative (the profile's
    air equals the ISA's to ~1e-15; the rest is the flight's sensitivity to it)."""
    run = jax.jit(lambda p: simulate_one(p, sim_settings(lynx_campaign))[0])
    profile = isa_profile(np.arange(0.0, 11001.0, 500.0))
    env = dataclasses.replace(lynx_params.environment, atmosphere=profile)
    got, want = run(dataclasses.replace(lynx_params, environment=env)), run(lynx_params)
    np.testing.assert_allclose(got["apogee_agl_m"], want["apogee_agl_m"], rtol=1e-9)
    distance = math.hypot(want["impact_north_m"], want["impact_east_m"])
    for name in ("impact_north_m", "impact_east_m"):
        assert abs(got[name] - want[name]) <= 1e-9 * distance, name
    assert float(want["apogee_agl_m"]) > 1000.0


def test_the_day_s_wind_turned_and_scaled(tmp_path):
    """wind_rotation_deg adds to every level's from-direction, wind_scale multiplies its speed."""
    text = (ROOT / "campaigns" / "lynx_euroc_sounding.toml").read_text()
    text = text.replace('file = "euroc_2023', 'wind_rotation_deg = 90.0\nwind_scale = 2.0\nfile = "euroc_2023')
    text = "\n".join(line for line in text.splitlines() if not line.startswith('"environment.atmosphere'))
    (tmp_path / "c.toml").write_text(text)
    campaign = load_campaign(tmp_path / "c.toml")
    w, wind = campaign.weather, nominal_params(campaign).environment.wind
    k = 6  # 850 hPa, 1564 m
    height = 6356766.0 * w.geopotential_height_m[k] / (6356766.0 - w.geopotential_height_m[k]) - 160.0
    got = wind.velocity_n(jnp.asarray(height))
    # from 227° turned to 317°: blowing toward 137°, at twice 27 kt
    speed, to = 2.0 * 27 * KNOT, math.radians(227.0 + 90.0 - 180.0)
    np.testing.assert_allclose([got.x, got.y], [speed * math.cos(to), speed * math.sin(to)], rtol=1e-6)


@pytest.mark.slow
def test_a_sounding_campaign_flies_end_to_end(tmp_path, capsys):
    out = tmp_path / "s.h5"
    assert main(["run", str(ROOT / "campaigns" / "lynx_euroc_sounding.toml"), "-n", "16", "--out", str(out),
                 "--quiet"]) == 0  # fmt: skip
    with h5py.File(out) as f:
        status, apogee = f["outputs/status"][:], f["outputs/apogee_agl_m"][:]
        assert set(f["inputs"]) == {"environment.atmosphere.wind_rotation_deg", "environment.atmosphere.wind_scale",
                                    "rocket.dry_mass_kg", "rocket.motor.thrust_scale", "rocket.aero.drag_scale",
                                    "launch.elevation_deg"}  # fmt: skip
    assert np.all(status == 0) and np.all((2500.0 < apogee) & (apogee < 3500.0))  # EuRoC 2021 flew 3076 m


# ------------------------------------------------------------------------------------------------ bad input


def campaign_with(tmp_path: Path, atmosphere: str, extra: str = "") -> Path:
    text = (ROOT / "campaigns" / "lynx_euroc_sounding.toml").read_text()
    text = text.replace('file = "euroc_2023-10-13_12z_era5_uwyo.txt"\n', atmosphere + "\n" + extra)
    (tmp_path / "c.toml").write_text(text)
    return tmp_path / "c.toml"


def refused(tmp_path, capsys, campaign: Path, *needles):
    assert main(["run", str(campaign), "-n", "8", "--out", str(tmp_path / "x.h5")]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and all(n in err for n in needles), err
    assert not (tmp_path / "x.h5").exists() and not (tmp_path / "x.h5.partial").exists()


def netcdf_without_u(path: Path) -> None:
    with scipy.io.netcdf_file(path, "w") as f:
        for name, n in (("time", 1), ("level", 2), ("latitude", 2), ("longitude", 2)):
            f.createDimension(name, n)
        f.createVariable("time", "i", ("time",))[:] = [1085052]
        f.variables["time"].units = b"hours since 1900-01-01 00:00:00.0"
        f.createVariable("level", "i", ("level",))[:] = [1000, 850]
        f.createVariable("latitude", "f", ("latitude",))[:] = [40.0, 39.0]
        f.createVariable("longitude", "f", ("longitude",))[:] = [-9.0, -8.0]
        for name in ("z", "t", "v"):
            f.createVariable(name, "f", ("time", "level", "latitude", "longitude"))[:] = 1.0


@pytest.mark.parametrize("case", ["malformed", "decreasing", "no-u", "late", "no-time", "two-winds", "wind-dispersed"])
def test_bad_weather_is_one_line_and_no_file(tmp_path, capsys, case):
    text = SOUNDING.read_text()
    if case == "malformed":
        (tmp_path / "s.txt").write_text(text.replace("  850.0   1564   16.4", "  850.0   1564   1x.4"))
        refused(tmp_path, capsys, campaign_with(tmp_path, 'file = "s.txt"'), "environment.atmosphere.file",
                "s.txt", "TEMP is not a number")
    elif case == "decreasing":
        (tmp_path / "s.txt").write_text(text.replace("  850.0   1564", "  850.0   1164"))
        refused(tmp_path, capsys, campaign_with(tmp_path, 'file = "s.txt"'), "environment.atmosphere.file",
                "s.txt", "HGHT must increase")
    elif case == "no-u":
        netcdf_without_u(tmp_path / "w.nc")
        refused(tmp_path, capsys, campaign_with(tmp_path, 'file = "w.nc"\ntime_utc = "2023-10-13T12:00:00Z"'),
                "environment.atmosphere.file", "w.nc", "no variable u")
    elif case == "late":
        refused(tmp_path, capsys, campaign_with(tmp_path, 'file = "euroc_2023_all_windows.nc"\n'
                                                          'time_utc = "2023-10-16T12:00:00Z"'),
                "environment.atmosphere.time_utc", "euroc_2023_all_windows.nc", "outside the file's times")
    elif case == "no-time":
        refused(tmp_path, capsys, campaign_with(tmp_path, 'file = "euroc_2025_era5_pressure_levels.nc"'),
                "environment.atmosphere.time_utc", "give the launch's time_utc")
    elif case == "two-winds":
        refused(tmp_path, capsys, campaign_with(tmp_path, 'file = "euroc_2023-10-13_12z_era5_uwyo.txt"',
                                                '[environment.wind]\nmodel = "constant"\nspeed_mps = 3.0\n'
                                                'from_deg = 0.0\n'),
                "environment", "remove [environment.wind]")
    else:
        path = campaign_with(tmp_path, 'file = "euroc_2023-10-13_12z_era5_uwyo.txt"')
        text = path.read_text().replace("[dispersions]\n", '[dispersions]\n"environment.wind.layers.0.speed_mps" = '
                                                           '{ dist = "uniform", low = 0.0, high = 5.0 }\n')
        path.write_text(text)
        assert tomllib.loads(text)["dispersions"]
        refused(tmp_path, capsys, path, "dispersions.environment.wind.layers.0.speed_mps", "wind_rotation_deg")

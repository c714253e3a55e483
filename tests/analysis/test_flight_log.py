"""The vendored Roccaraso 2021 Lynx log: reader, reduction, ISA pressure altitude and wind-profile CSV.

References: the CSV files themselves (read here with the csv module), the derived figures of
data/flights/roccaraso_2021/SOURCE.md, the ISA forward model and the hypsometric closed form, and
the log's other sensors (GNSS Doppler velocity, pitot static port) where the barometer is checked.
"""

import csv
import math
import shutil

import numpy as np
import pytest

from rocketmc.analysis.flight_log import (
    ROCCARASO_2021,
    ROCCARASO_SITE,
    load_roccaraso_2021,
    pressure_altitude_agl_m,
    read_flight_log,
    reduce_flight,
    write_wind_profile_csv,
)
from rocketmc.env.atmosphere import isa
from rocketmc.env.wind import WindProfile, read_wind_profile

# stream -> (file, rows, period [s], columns after t_s, in the CSV's order)
STREAMS = {
    "imu": ("imu_bmx160_50hz.csv", 6463, 0.020,
            ["accel_x_mps2", "accel_y_mps2", "accel_z_mps2", "gyro_x_radps", "gyro_y_radps", "gyro_z_radps",
             "mag_x_ut", "mag_y_ut", "mag_z_ut"]),
    "baro": ("baro_ms5803_66hz.csv", 8615, 0.015, ["pressure_pa"]),
    "pitot": ("pitot_42hz.csv", 5384, 0.024, ["static_pressure_pa", "airspeed_mps"]),
    "gnss": ("gps_neom9n_25hz.csv", 3230, 0.040,
             ["latitude_deg", "longitude_deg", "v_north_mps", "v_east_mps", "v_down_mps", "satellites"]),
}  # fmt: skip
IMU_PERIOD_S, BARO_PERIOD_S, PITOT_PERIOD_S = 0.020, 0.015, 0.024


@pytest.fixture(scope="module")
def log():
    return load_roccaraso_2021()


@pytest.fixture(scope="module")
def reduction(log):
    return reduce_flight(log)


def _csv_rows(name):
    with (ROCCARASO_2021 / name).open() as f:
        return [[float(x) for x in row] for row in list(csv.reader(f))[1:]]


def _mean_in(df, column, start, end):
    return df[column][(df.t_s >= start) & (df.t_s <= end)].mean()


@pytest.mark.parametrize("stream", STREAMS)
def test_reader_matches_the_csv(log, stream):
    file, rows, period, columns = STREAMS[stream]
    frame, raw = getattr(log, stream), _csv_rows(file)
    assert list(frame.columns) == ["t_s", *columns]
    assert frame.shape == (rows, 1 + len(columns)) and len(raw) == rows
    np.testing.assert_allclose(np.diff(frame.t_s), period, rtol=0, atol=1e-12)
    for k in (0, 1, rows - 1):  # sample, t_nominal_s, values...
        assert frame.t_s.iloc[k] == pytest.approx(raw[k][0] * period, abs=1e-12)
        assert frame.t_s.iloc[k] == pytest.approx(raw[k][1], abs=5e-4)  # CSV time has 3 decimals
        np.testing.assert_array_equal(frame.iloc[k, 1:].to_numpy(dtype=float), raw[k][2:])


def test_site_and_description(log):
    assert log.site == ROCCARASO_SITE
    assert (log.site.latitude_deg, log.site.longitude_deg, log.site.altitude_m) == (41.8087, 14.0543, 1416.0)
    assert "Roccaraso" in log.description and "L1350" in log.description


def test_pressure_altitude_inverts_the_isa():
    pad = 1416.0
    z = pad + np.linspace(-200.0, 3000.0, 33)
    heights = pressure_altitude_agl_m(np.asarray(isa(z).pressure), float(isa(pad).pressure))
    np.testing.assert_allclose(heights, z - pad, rtol=0, atol=1e-6)


def test_pressure_altitude_is_the_hypsometric_closed_form():
    # US 1976 troposphere: T = T_pad − L·ΔH over geopotential height ΔH above the pad, so
    # ΔH = (T_pad / L)·(1 − (p / p_pad)^(R·L/g0)); geometric z = r·H / (r − H).
    lapse, r_gas, g0, radius = 0.0065, 287.05287, 9.80665, 6356766.0
    p_pad = 85681.5859  # Roccaraso baro sample 0
    h_pad = 288.15 / lapse * (1.0 - (p_pad / 101325.0) ** (r_gas * lapse / g0))  # pad's ISA pressure height
    t_pad = 288.15 - lapse * h_pad
    p = np.linspace(0.80, 1.02, 23) * p_pad
    h = h_pad + t_pad / lapse * (1.0 - (p / p_pad) ** (r_gas * lapse / g0))

    def geometric(h):
        return radius * h / (radius - h)

    np.testing.assert_allclose(pressure_altitude_agl_m(p, p_pad), geometric(h) - geometric(h_pad), rtol=0, atol=1e-6)


def test_boost_figures_match_source(reduction):
    # SOURCE.md: burnout ≈ 3.2 s (quoted to 0.1 s; the IMU samples every 20 ms and the zero crossing
    # of the axial specific force is interpolated), peak 81.5 m/s² at ≈ 1.1 s (one sample, 1.14 s),
    # peak pitot airspeed 202 m/s (to 1 m/s) at ≈ 3.1 s (one pitot period, 24 ms).
    assert reduction.burnout_time_s == pytest.approx(3.2, abs=0.05)
    assert reduction.burnout_time_s < 3.28  # before the L1350's nominal burn time ends
    assert reduction.max_axial_specific_force_mps2 == pytest.approx(81.5, abs=0.05)
    assert reduction.max_axial_specific_force_time_s == pytest.approx(1.1, abs=0.05)
    assert reduction.max_airspeed_mps == pytest.approx(202.0, abs=0.5)
    assert reduction.max_airspeed_time_s == pytest.approx(3.1, abs=PITOT_PERIOD_S)


def test_deployment_events_match_source(reduction):
    # SOURCE.md: drogue spike at ≈ 18.2 s (one IMU sample earlier still rounds there), main spikes
    # from 61.5 to 62.2 s; the main opens below ~350 m AGL.
    assert reduction.drogue_time_s == pytest.approx(18.2, abs=0.05)
    assert 61.5 - IMU_PERIOD_S <= reduction.main_time_s <= 62.2
    main_agl = np.interp(reduction.main_time_s, reduction.altitude.t_s, reduction.altitude.altitude_agl_m)
    assert 300.0 < main_agl < 370.0


def test_apogee(log, reduction):
    altitude = reduction.altitude
    # SOURCE.md's "about 1425 m at 19.1 s" is the highest baro sample. It lies 0.9 s after the drogue
    # shock, on the deployment's pressure transient. Same sample here; our ISA formula reads 1.7 m
    # higher (ISA temperature at the pad's pressure level 279.10 K against 278.95 K, geometric metres).
    k = altitude.altitude_agl_m.idxmax()
    assert altitude.t_s[k] == pytest.approx(19.1, abs=BARO_PERIOD_S)
    assert altitude.altitude_agl_m[k] == pytest.approx(1425.0, abs=4.0)
    # The reduced apogee comes before the shock; the GNSS Doppler climb rate, an independent sensor,
    # crosses zero within 0.1 s of it (GNSS latency and 40 ms samples).
    assert reduction.apogee_time_s < reduction.drogue_time_s
    t, v_down = log.gnss.t_s.to_numpy(), log.gnss.v_down_mps.to_numpy()
    j = np.flatnonzero((t > 10.0) & (v_down > 0.0))[0]
    gnss_apogee = t[j - 1] + (t[j] - t[j - 1]) * -v_down[j - 1] / (v_down[j] - v_down[j - 1])
    assert reduction.apogee_time_s == pytest.approx(gnss_apogee, abs=0.1)
    # The vertex sits on the baro samples: within 0.5 m (noise ~0.3 m) of their mean over ±0.25 s,
    # where the ballistic curve drops by only g·0.25²/2 = 0.3 m.
    near = _mean_in(altitude, "altitude_agl_m", reduction.apogee_time_s - 0.25, reduction.apogee_time_s + 0.25)
    assert reduction.apogee_agl_m == pytest.approx(near + 0.1, abs=0.5)


def test_descent_rates(log, reduction):
    altitude = reduction.altitude
    # SOURCE.md: drogue descent ≈ 25.6 m/s over 30–40 s (quoted to 0.1 m/s).
    assert -_mean_in(altitude, "vertical_speed_mps", 30.0, 40.0) == pytest.approx(25.6, abs=0.1)
    start, end = reduction.drogue_window_s
    assert start == reduction.drogue_time_s + 10.0 and end == reduction.main_time_s - 1.0
    start, end = reduction.main_window_s
    assert start == reduction.main_time_s + 5.0 and end == reduction.landing_time_s - 2.0
    # The GNSS Doppler descent rate is 3.6 % (drogue) and 6 % (main) faster: the baro heights are ISA
    # pressure heights, which fall short of geometric ones by T/T_ISA on a day warmer than the ISA.
    for window, rate in ((reduction.drogue_window_s, reduction.drogue_descent_rate_mps),
                         (reduction.main_window_s, reduction.main_descent_rate_mps)):  # fmt: skip
        assert 1.0 < _mean_in(log.gnss, "v_down_mps", *window) / rate < 1.08
    assert 25.0 < reduction.drogue_descent_rate_mps < 27.0 and 4.5 < reduction.main_descent_rate_mps < 7.0


def test_landing(log, reduction):
    landing, altitude = reduction.landing_time_s, reduction.altitude
    assert reduction.main_time_s + 30.0 < landing < 110.0
    # Descending before the shock, still after it (baro and GNSS).
    assert -_mean_in(altitude, "vertical_speed_mps", landing - 5.0, landing - 1.0) > 3.0
    assert abs(_mean_in(altitude, "vertical_speed_mps", landing + 2.0, 130.0)) < 0.3
    after = log.gnss[log.gnss.t_s > landing + 1.0]
    assert np.hypot(after.v_north_mps, after.v_east_mps).max() < 1.0
    # The ground is ~92 m above the pad; the pitot static port, another sensor, agrees within 4 %
    # (the two disagree by that much on every pressure difference of the flight, SOURCE.md's apogees).
    static = log.pitot.static_pressure_pa
    ground = pressure_altitude_agl_m(static[log.pitot.t_s > landing + 2.0].median(), static.iloc[0])
    assert reduction.landing_agl_m == pytest.approx(ground, rel=0.04)
    # Landing point: the WGS84 tangent-plane offset against the haversine distance and initial bearing
    # on a 6371 km sphere; at 41.8° the ellipsoid's radii of curvature differ from the sphere's by
    # −0.1 % (meridian) and +0.3 % (prime vertical), which moves distances by < 0.3 % and bearings by
    # < 3 mrad.
    lat0, lon0 = map(math.radians, (ROCCARASO_SITE.latitude_deg, ROCCARASO_SITE.longitude_deg))
    lat1, lon1 = (math.radians(np.interp(landing, log.gnss.t_s, log.gnss[c])) for c in ("latitude_deg", "longitude_deg"))
    a = math.sin((lat1 - lat0) / 2) ** 2 + math.cos(lat0) * math.cos(lat1) * math.sin((lon1 - lon0) / 2) ** 2
    distance = 2 * 6371008.8 * math.asin(math.sqrt(a))
    bearing = math.atan2(math.sin(lon1 - lon0) * math.cos(lat1),
                         math.cos(lat0) * math.sin(lat1) - math.sin(lat0) * math.cos(lat1) * math.cos(lon1 - lon0))  # fmt: skip
    assert math.hypot(reduction.landing_north_m, reduction.landing_east_m) == pytest.approx(distance, rel=3e-3)
    assert math.atan2(reduction.landing_east_m, reduction.landing_north_m) == pytest.approx(bearing, abs=3e-3)
    assert 900.0 < distance < 1100.0


def test_series(log, reduction):
    assert list(reduction.axial_specific_force) == ["t_s", "specific_force_mps2"]
    np.testing.assert_array_equal(reduction.axial_specific_force.specific_force_mps2, log.imu.accel_x_mps2)
    assert list(reduction.airspeed) == ["t_s", "airspeed_mps"]
    assert list(reduction.gnss_velocity) == ["t_s", "v_north_mps", "v_east_mps", "v_down_mps"]
    assert list(reduction.altitude) == ["t_s", "altitude_agl_m", "vertical_speed_mps"]
    assert reduction.altitude.altitude_agl_m[0] == 0.0


def test_wind_profile(log, reduction):
    altitude, speed, from_deg = reduction.wind_profile
    assert np.all(np.diff(altitude) > 0) and altitude[0] > reduction.landing_agl_m and altitude[-1] < 1300.0
    assert len(altitude) >= 9
    # From the west-north-west at 6–10 m/s: the canopies drift east-south-east (landing point).
    assert np.all((speed > 5.0) & (speed < 10.0)) and np.all((from_deg > 260.0) & (from_deg < 310.0))
    # One bin by hand: the GNSS samples under the drogue between 500 and 600 m.
    g = log.gnss
    h = np.interp(g.t_s, reduction.altitude.t_s, reduction.altitude.altitude_agl_m)
    start, end = reduction.drogue_window_s
    inside = (g.t_s >= start) & (g.t_s <= end) & (h >= 500.0) & (h < 600.0)
    north, east = g.v_north_mps[inside].mean(), g.v_east_mps[inside].mean()
    k = np.flatnonzero((altitude >= 500.0) & (altitude < 600.0))[0]
    assert speed[k] == pytest.approx(math.hypot(north, east), rel=1e-12)
    # rocketmc's wind model, fed the profile, blows the air the way the rocket drifted.
    model = WindProfile.from_speed_direction(altitude, speed, np.deg2rad(from_deg))
    wind = model.velocity_n(altitude[k])
    assert (float(wind.x), float(wind.y)) == pytest.approx((north, east), abs=1e-9)


def test_wind_profile_round_trips_through_read_wind_profile(reduction, tmp_path):
    path = tmp_path / "wind.csv"
    write_wind_profile_csv(path, reduction.wind_profile, comment="GNSS drift under the canopies")
    assert path.read_text().splitlines()[:2] == ["# GNSS drift under the canopies", "altitude_agl_m,speed_mps,from_deg"]
    altitude, speed, from_rad = read_wind_profile(path, ROCCARASO_SITE.altitude_m)
    expected_altitude, expected_speed, expected_from = reduction.wind_profile
    np.testing.assert_allclose(altitude, expected_altitude, atol=0.05)  # written to 0.1 m
    np.testing.assert_allclose(speed, expected_speed, atol=0.005)  # 0.01 m/s
    np.testing.assert_allclose(np.rad2deg(from_rad), expected_from, atol=0.05)  # 0.1°


def _copy_of_log(tmp_path):
    root = tmp_path / "log"
    root.mkdir()
    for file, *_ in STREAMS.values():
        shutil.copyfile(ROCCARASO_2021 / file, root / file)
    return root


def test_missing_file_is_named(tmp_path):
    root = _copy_of_log(tmp_path)
    (root / "pitot_42hz.csv").unlink()
    with pytest.raises(FileNotFoundError, match="pitot_42hz.csv"):
        read_flight_log(root, ROCCARASO_SITE, "")


@pytest.mark.parametrize(
    "edit, message",
    [
        (lambda text: text.replace("85698.3438", "85698.34x"), "finite numbers"),
        (lambda text: text.replace("pressure_pa", "pressure"), "missing columns pressure_pa"),
        (lambda text: text.replace("\n2,0.030,", "\n3,0.030,", 1), "sample must count"),
        (lambda text: text.replace("0,0.000,", "0,0.005,", 1), "t_nominal_s"),
        (lambda text: "", "not a CSV table"),
    ],
)
def test_corrupt_file_is_named(tmp_path, edit, message):
    root = _copy_of_log(tmp_path)
    path = root / "baro_ms5803_66hz.csv"
    path.write_text(edit(path.read_text()))
    with pytest.raises(ValueError, match=f"baro_ms5803_66hz.csv: .*{message}"):
        read_flight_log(root, ROCCARASO_SITE, "")

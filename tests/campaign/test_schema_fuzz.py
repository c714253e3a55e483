"""Fuzzed campaigns: every number finite and in its physical range, every value a dispersion
can draw valid, the name a label, broken input files refused: each as one ConfigError line naming the
field, checked at load time. No flight is flown."""

import copy
import math
import re
import tomllib
from pathlib import Path

import h5py
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rocketmc.aero.io import lynx_datcom_tables, save_aero_tables
from rocketmc.campaign import ConfigError, campaign_from_dict, load_campaign
from rocketmc.campaign.limits import MAX_NAME_LENGTH, MAX_REALIZATIONS, MIN_CONTROL_DT_S, MIN_MASS_KG, NORMAL_REACH_STD
from rocketmc.campaign.loader import flatten_numbers, preset_rocket
from rocketmc.campaign.schema import GncConfig, GuidanceConfig, ServoConfig
from rocketmc.cli import main

ROOT = Path(__file__).parents[2]
CAMPAIGNS = ROOT / "campaigns"
SHIPPED = sorted(CAMPAIGNS.glob("*.toml")) + sorted((ROOT / "src" / "rocketmc" / "data" / "campaigns").glob("*.toml"))
NOMINAL = (CAMPAIGNS / "lynx_nominal.toml").read_text()
RAW = tomllib.loads(NOMINAL)
assert RAW["rocket"] == {"preset": "lynx"}  # so that EXPANDED is the same campaign
EXPANDED = {**RAW, "rocket": preset_rocket("lynx")}
"""lynx_nominal with the preset's rocket written out: every number of the campaign is a leaf."""
BINARY = bytes(range(256)) * 4  # 0x80-0xff alone are not UTF-8; NUL and other control bytes besides
FIELD_PREFIX = re.compile(r"^[a-z_]+(\.[A-Za-z0-9_]+)*: ")
"""How every ConfigError starts: the dotted path of the field (or a top-level key), a colon."""


def replaced(raw: dict, keys, value) -> dict:
    """A copy of ``raw`` with the leaf at ``keys`` (a dotted path, or a tuple where a key holds dots) set."""
    keys = keys.split(".") if isinstance(keys, str) else keys
    raw = copy.deepcopy(raw)
    node = raw
    for key in keys[:-1]:
        node = node[int(key)] if isinstance(node, list) else node[key]
    if isinstance(node, list):
        node[int(keys[-1])] = value
    else:
        node[keys[-1]] = value
    return raw


def with_dispersion(path: str, **dispersion) -> dict:
    """The expanded nominal campaign with the dispersion of ``path`` replaced (or added)."""
    return {**EXPANDED, "dispersions": {**EXPANDED["dispersions"], path: dispersion}}


def refusal(raw: dict, base_dir: Path = CAMPAIGNS) -> str:
    """The message of the ConfigError that loading ``raw`` raises, checked to be one line."""
    with pytest.raises(ConfigError) as info:
        campaign_from_dict(raw, base_dir)
    message = str(info.value)
    assert "\n" not in message and FIELD_PREFIX.match(message), message
    return message


def test_expanded_nominal_is_valid():
    """The base of every case below loads: each refusal is the edit's doing."""
    campaign = campaign_from_dict(EXPANDED, CAMPAIGNS)
    assert campaign.nominal == campaign_from_dict(RAW, CAMPAIGNS).nominal


@pytest.mark.parametrize("path", SHIPPED, ids=lambda p: str(p.relative_to(ROOT)))
def test_shipped_campaigns_still_load(path):
    assert load_campaign(path).config.n_realizations >= 1


NUMBER_FIELDS = [
    "environment.wind.layers.0.speed_mps",
    "environment.wind.layers.2.from_deg",
    "environment.wind.layers.1.thickness_m",
    "environment.turbulence.severity",
    "rocket.motor.thrust_scale",
    "rocket.motor.ignition_delay_s",
    "rocket.dry_mass_kg",
    "rocket.dry_inertia_kgm2.1",
    "rocket.aero.cd.3",
    "rocket.aero.linear.cm_q",
    "rocket.geometry.fins.0.span_m",
    "rocket.parachutes.1.area_m2",
    "launch.rail_length_m",
    "site.altitude_m",
    "simulation.max_time_s",
]


@pytest.mark.parametrize("value", [math.inf, -math.inf, math.nan], ids=["inf", "-inf", "nan"])
@pytest.mark.parametrize("path", NUMBER_FIELDS)
def test_non_finite_numbers_are_refused_naming_the_field(path, value):
    message = refusal(replaced(EXPANDED, path, value))
    assert message.startswith(f"{path}: Input should be a finite number"), message


@pytest.mark.parametrize(
    ("path", "value", "words"),
    [
        ("environment.wind.layers.0.speed_mps", 1e4, "less than or equal to"),  # 10 km/s: no wind on Earth
        ("environment.turbulence.w20_mps", 1e3, "less than or equal to"),
        ("rocket.motor.thrust_scale", 100.0, "less than or equal to"),  # a unit slip, not a motor lot
        ("rocket.motor.thrust_scale", 0.0, "greater than 0"),
        ("rocket.motor.ignition_delay_s", 1e6, "less than or equal to"),  # 11 days on the pad
        ("rocket.motor.ignition_delay_s", -1.0, "greater than or equal to 0"),
        ("simulation.max_time_s", 1e9, "less than or equal to"),  # 30 years of flight
        ("simulation.control_dt_s", 1e-9, f"greater than or equal to {MIN_CONTROL_DT_S}"),  # 10⁹ Hz: never ends
        ("rocket.dry_mass_kg", 1e6, "less than or equal to"),  # a thousand tonnes
        ("rocket.dry_mass_kg", 1e-30, f"greater than or equal to {MIN_MASS_KG}"),
        ("rocket.dry_inertia_kgm2.0", 0.0, "greater than or equal to"),
        ("rocket.geometry.length_m", 1e3, "less than or equal to"),  # a kilometre-long rocket
        ("rocket.geometry.body_diameter_m", -0.15, "greater than or equal to"),
        ("rocket.parachutes.0.cd", 50.0, "less than or equal to"),  # 20 × the draggiest canopy
        ("rocket.parachutes.1.area_m2", 1e5, "less than or equal to"),  # 10 ha of canopy
        ("rocket.parachutes.0.delay_s", -0.5, "greater than or equal to 0"),
        ("rocket.aero.drag_scale", 1e3, "less than or equal to"),
        ("rocket.aero.cd_mach.5", 1e3, "less than or equal to"),  # Mach 1000
        ("rocket.aero.linear.cm_q", -1e9, "greater than or equal to"),
        ("rocket.aero.linear.cn_alpha", 1e6, "less than or equal to"),
        ("launch.rail_length_m", 0.0, "greater than or equal to"),
        ("n_realizations", 10**12, f"less than or equal to {MAX_REALIZATIONS}"),
    ],
)  # fmt: skip
def test_absurd_magnitudes_are_refused_naming_the_field(path, value, words):
    message = refusal(replaced(EXPANDED, path, value))
    assert message.startswith(f"{path}: ") and words in message, message


@pytest.mark.parametrize("key, value, field, words", [
    ("fins.0.position_m", 2.2, "rocket.geometry.fins.0.position_m", "outside the body"),  # root ends 0.055 m past the tail
    ("fins.0.position_m", -0.1, "rocket.geometry.fins.0.position_m", "outside the body"),  # ahead of the nose tip
    ("canards.position_m", 2.4, "rocket.geometry.canards.position_m", "outside the body"),
    ("canards.position_m", 2.0, "rocket.geometry.canards.position_m", "overlaps fins.0"),  # 2.0-2.15 against 2.145-2.495
    ("boat_tail", {"length_m": 0.1, "aft_diameter_m": 0.1, "position_m": 2.45}, "rocket.geometry.boat_tail.position_m",
     "aft end"),
    ("boat_tail", {"length_m": 0.1, "aft_diameter_m": 0.2, "position_m": 2.395}, "rocket.geometry.boat_tail.aft_diameter_m",
     "narrows"),
])  # fmt: skip
def test_geometry_that_cannot_be_built(key, value, field, words):
    """A fin set past the tail or ahead of the nose, canards outside the body or over the fins, a boat-tail past
    the aft end or widening: one line naming the field, before any table is built."""
    message = refusal(replaced(EXPANDED, f"rocket.geometry.{key}", value))
    assert message.startswith(f"{field}: ") and words in message, message


def test_geometry_that_just_fits_is_accepted():
    """The limits are inclusive: a fin set ending at the aft end, canards touching it, a boat-tail ending there."""
    raw = replaced(EXPANDED, "rocket.geometry.fins.0.position_m", 2.145)
    raw = replaced(raw, "rocket.geometry.canards.position_m", 2.145 - 0.15)
    raw = replaced(raw, "rocket.geometry.boat_tail", {"length_m": 0.1, "aft_diameter_m": 0.12, "position_m": 2.395})
    campaign_from_dict(raw, CAMPAIGNS)


def test_geometry_and_power_law_consistency():
    """A nose longer than the rocket (it divided by zero in the build-up) and a power-law reference
    height below the 1 m the law is held at (the stated speed would never be flown) are refused."""
    message = refusal(replaced(EXPANDED, "rocket.geometry.nose.length_m", 3.0))
    assert message.startswith("rocket.geometry: nose.length_m (3.0) exceeds length_m (2.495)"), message
    campaign_from_dict(replaced(EXPANDED, "rocket.geometry.nose.length_m", 2.495), CAMPAIGNS)  # a nose-only body
    wind = {"model": "power_law", "speed_mps": 6.0, "from_deg": 270.0, "reference_height_m": 0.01}
    raw = {**replaced(EXPANDED, "environment.wind", wind), "dispersions": {}}
    assert refusal(raw).startswith("environment.wind.reference_height_m: Input should be greater than or equal to 1")


@pytest.mark.parametrize(
    ("key", "value"), [("std", math.inf), ("std", math.nan), ("low", -math.inf), ("high", math.inf), ("mean", math.nan)]
)
def test_non_finite_dispersion_parameters_are_refused(key, value):
    dispersion = {"dist": "normal", "std": 0.03, "low": 0.85, "high": 1.15, key: value}
    message = refusal(with_dispersion("rocket.motor.thrust_scale", **dispersion))
    assert message.startswith(f"dispersions.rocket.motor.thrust_scale.{key}: Input should be a finite number"), message


def test_non_finite_uniform_and_choice_parameters_are_refused():
    uniform = with_dispersion("environment.wind.layers.0.speed_mps", dist="uniform", low=0.0, high=math.inf)
    assert refusal(uniform).startswith("dispersions.environment.wind.layers.0.speed_mps.high: Input should be a finite")
    choice = with_dispersion("environment.turbulence.severity", dist="choice", values=[0.0, math.nan])
    assert refusal(choice).startswith("dispersions.environment.turbulence.severity.values.1: Input should be a finite")


def test_normal_clip_range_must_contain_the_mean():
    """thrust_scale's nominal is 1: a clip range [1.05, 1.15] would draw 1.05 far more often than anything else."""
    message = refusal(with_dispersion("rocket.motor.thrust_scale", dist="normal", std=0.03, low=1.05, high=1.15))
    assert message == ("dispersions.rocket.motor.thrust_scale: the clip range [1.05, 1.15] excludes the mean 1.0 "
                       "(the nominal value, as no mean is given)"), message  # fmt: skip
    message = refusal(with_dispersion("rocket.motor.thrust_scale", dist="normal", mean=0.8, std=0.03, low=0.85))
    assert message == "dispersions.rocket.motor.thrust_scale: the clip range [0.85, None] excludes the mean 0.8"
    campaign_from_dict(with_dispersion("rocket.motor.thrust_scale", dist="normal", std=0.03, low=1.0, high=1.15))


def test_unclipped_normal_is_checked_at_six_std():
    """dry mass 18.362 kg, std 5 kg, no low: 6·std below the mean is a negative mass. Clipping that side is
    the fix; the high side, unclipped, is checked too (elevation 84° + 6 · 2° > 90°)."""
    message = refusal(with_dispersion("rocket.dry_mass_kg", dist="normal", std=5.0))
    assert message.startswith("dispersions.rocket.dry_mass_kg: draws a value -11.63") and "clip it with low" in message
    assert "rocket.dry_mass_kg: Input should be greater than or equal to" in message, message
    campaign_from_dict(with_dispersion("rocket.dry_mass_kg", dist="normal", std=5.0, low=10.0))
    message = refusal(with_dispersion("launch.elevation_deg", dist="normal", std=2.0))
    assert "mean + 6·std; clip it with high" in message and "launch.elevation_deg: Input should be less" in message


def test_a_sensor_spread_drawing_out_of_range_names_the_spread():
    """A per-flight spread is a dispersion the file does not write (``sensor_spreads``): a gyroscope misaligned by
    2° per flight draws 6·2° beyond misalignment_deg's ±10°; the line names the spread the file gives, and the way
    out it offers (a dispersion of the drawn value, clipped) loads."""
    raw = {**EXPANDED, "avionics": {"gyroscope": {"misalignment_std_deg": 2.0}}}
    message = refusal(raw)
    assert message.startswith("avionics.gyroscope.misalignment_std_deg: draws -12.0 (the nominal − 6·std), out of "
                              "range: avionics.gyroscope.misalignment_deg.0: Input should be greater than or equal to "
                              "-10"), message  # fmt: skip
    clipped = {f"avionics.gyroscope.misalignment_deg.{i}": {"dist": "normal", "std": 2.0, "low": -10.0, "high": 10.0}
               for i in range(3)}  # fmt: skip
    campaign = campaign_from_dict({**raw, "dispersions": {**EXPANDED["dispersions"], **clipped}}, CAMPAIGNS)
    assert campaign.config.dispersions["avionics.gyroscope.misalignment_deg.1"].low == -10.0


@pytest.mark.parametrize(("factor", "valid"), [(0.99, True), (1.01, False)])
def test_unclipped_reach_is_six_std_exactly(factor, valid):
    """Drogue cd 0.9 (> 0): std = factor · 0.9/6 puts mean − 6·std just inside or just outside the range;
    1 % either side so that the float rounding of 6·std cannot decide."""
    raw = with_dispersion("rocket.parachutes.0.cd", dist="normal", std=factor * 0.9 / NORMAL_REACH_STD, high=1.3)
    if valid:
        campaign_from_dict(raw, CAMPAIGNS)
    else:
        assert refusal(raw).startswith("dispersions.rocket.parachutes.0.cd: draws a value -0.009")


@pytest.mark.parametrize("name", ["../../etc/passwd", "a/b\\c", "x" * MAX_NAME_LENGTH, "Lynx à Roccaraso — 2021"])
def test_a_name_is_a_label_kept_as_given(name):
    """Slashes and dots are a label's business (the CLI derives a file name from it); it loads verbatim."""
    assert campaign_from_dict({**EXPANDED, "name": name}, CAMPAIGNS).config.name == name


@pytest.mark.parametrize(
    "name", ["", "   ", "two\nlines", "tab\there", "nul\x00", "x" * (MAX_NAME_LENGTH + 1), "x" * 10_000],
    ids=["empty", "blank", "newline", "tab", "nul", "129-characters", "10000-characters"],
)
def test_bad_names_are_one_line(name):
    message = refusal({**EXPANDED, "name": name})
    assert message.startswith(f"name: expected a label: 1 to {MAX_NAME_LENGTH} printable characters"), message
    assert len(message) < 300, message  # one readable line: a long name is shown shortened, not in full


def thrust_curve_campaign(tmp_path: Path, content: bytes | None, name: str = "motor.eng") -> dict:
    """The nominal campaign flying ``tmp_path / name`` (written with ``content``, a folder if None)."""
    target = tmp_path / name
    target.mkdir() if content is None else target.write_bytes(content)
    return replaced(EXPANDED, "rocket.motor.thrust_curve", name)


@pytest.mark.parametrize(
    ("name", "content", "words"),
    [
        ("motor.eng", BINARY, "not a UTF-8 text file"),
        ("motor.csv", b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR", "not a UTF-8 text file"),
        ("motor.rse", BINARY, "not a readable RockSim .rse file"),
        ("motor.eng", b"", "fewer than two thrust points"),
        ("motor.eng", None, "is not a file"),
        ("motor.eng", b"L1350 75 621 0 1.905 4.263 CTI\n0.02 1400\n0.0", "cannot read the line '0.0'"),
        ("motor.csv", b"0.1,100\n0.2", "cannot read the line"),
        ("motor.csv", b"0.0,0\n1.0,0\n", "total impulse must be positive"),  # ṁ = F·m_p0/I_tot
    ],
    ids=["binary-eng", "png-csv", "binary-rse", "empty", "folder", "truncated-eng", "truncated-csv", "no-impulse"],
)
def test_broken_thrust_files_name_the_field(tmp_path, name, content, words):
    message = refusal(thrust_curve_campaign(tmp_path, content, name), tmp_path)
    assert message.startswith("rocket.motor.thrust_curve: ") and words in message, message


@pytest.mark.parametrize(
    ("content", "words"),
    [
        (BINARY, "not a UTF-8 text file"),
        (b"altitude_agl_m,speed_mps,from_deg\n0,2,270\x00\n1000,12,270\n", "every row needs numbers"),
        (b"altitude_agl_m,speed_mps,from_deg\n" + b"7" * 200_000, "not a readable CSV file"),  # > csv's field limit
        (b"altitude_agl_m,speed_mps,from_deg\n0,2,270\n1000,", "every row needs numbers"),
        (b"", "expected columns"),
        (b"altitude_agl_m,speed_mps,from_deg\n0,2,270\n1000,1200,270\n", "speed_mps reaches 1200"),
    ],
    ids=["binary", "nul-byte", "huge-field", "truncated", "empty", "1200-mps"],
)
def test_broken_wind_profiles_name_the_field(tmp_path, content, words):
    (tmp_path / "wind.csv").write_bytes(content)
    wind = {"model": "profile", "file": "wind.csv", "speed_scale": 1.0}
    raw = {**replaced(EXPANDED, "environment.wind", wind), "dispersions": {}}
    message = refusal(raw, tmp_path)
    assert message.startswith("environment.wind.file: ") and words in message, message


@pytest.mark.parametrize(
    ("rocket", "message_start"),
    [
        ({"preset": "lynx", "motor": {"thrust_curve": "x" * 10_000}}, "rocket.motor.thrust_curve: cannot look up 'xxx"),
        ({"preset": "../rockets/lynx"}, "rocket.preset: unknown preset '../rockets/lynx' (available: lynx, lynx_2021, or a file name ending in .toml)"),
        ({"preset": "x" * 10_000}, "rocket.preset: unknown preset 'xxx"),
    ],
    ids=["long-file-name", "preset-path", "long-preset"],
)
def test_file_and_preset_names_are_names(rocket, message_start):
    """A file name too long for the file system and a preset given as a path are one line each."""
    message = refusal({**RAW, "rocket": rocket})
    assert message.startswith(message_start) and len(message) < 300, message  # the long name is shortened


def truncated_h5(tmp_path: Path) -> bytes:
    """The first half of a valid rocketmc aero table file."""
    save_aero_tables(tmp_path / "whole.h5", lynx_datcom_tables())
    data = (tmp_path / "whole.h5").read_bytes()
    assert h5py.is_hdf5(tmp_path / "whole.h5")
    return data[: len(data) // 2]


@pytest.mark.parametrize(
    ("name", "words"),
    [("aero.csv", "not a UTF-8 text file"), ("aero.h5", "not a readable HDF5 file"),
     ("truncated.h5", "not a readable HDF5 file"), ("aero.mat", "not a readable MATLAB .mat file")],
)  # fmt: skip
def test_broken_aero_tables_name_the_field(tmp_path, name, words):
    (tmp_path / name).write_bytes(truncated_h5(tmp_path) if name == "truncated.h5" else BINARY)
    aero = {"model": "interpolated", "tables": name}
    if name.endswith(".mat"):  # a .mat does not record its reference values
        aero.update(reference_area_m2=0.01767, reference_length_m=0.15, moment_reference_m=1.49)
    message = refusal(replaced(EXPANDED, "rocket.aero", aero), tmp_path)
    assert message.startswith(f"rocket.aero.tables: {tmp_path / name}: {words}"), message


@pytest.mark.parametrize(
    ("old", "new", "field"),
    [
        ("speed_mps = 7.5", "speed_mps = inf", "environment.wind.layers.0.speed_mps"),
        ('preset = "lynx"', 'preset = "lynx"\nmotor.thrust_scale = nan', "rocket.motor.thrust_scale"),
        ('preset = "lynx"', 'preset = "lynx"\nmotor.ignition_delay_s = inf', "rocket.motor.ignition_delay_s"),
        ("max_time_s = 300.0", "max_time_s = inf", "simulation.max_time_s"),
        ("std = 0.03, low = 0.85", "std = 0.03, low = 1.05", "dispersions.rocket.motor.thrust_scale"),
        ('name = "lynx_nominal"', 'name = "../lynx\\nnominal"', "name"),
        ('name = "lynx_nominal"', f'name = "{"x" * 10_000}"', "name"),
        ('preset = "lynx"', 'preset = "lynx"\nmotor.thrust_curve = "binary.eng"', "rocket.motor.thrust_curve"),
        ('preset = "lynx"', 'preset = "lynx"\naero.tables = "binary.csv"', "rocket.aero.tables"),
        ("elevation_deg = 84.0", "elevation_deg = 91.0", "launch.elevation_deg"),
        ('preset = "lynx"', 'preset = "lynx"\ndry_mass_kg = -3.0', "rocket.dry_mass_kg"),
        ("n_realizations = 1000\n", "", "n_realizations"),
        ("seed = 2021", "seed = 2021\ncolour = 'red'", "colour"),
        ('preset = "lynx"', 'preset = "lynx"\naero = { tables = "missing.h5" }', "rocket.aero.tables"),
        ('preset = "lynx"', 'preset = "lynx"\naero = { model = "fast" }', "rocket.aero.model"),
        ("[dispersions]", '[dispersions]\n"rocket.geometry.fins.0.span_m" = { dist = "normal", std = 0.01 }',
         "dispersions.rocket.geometry.fins.0.span_m"),
        ("chunk_size = 1000", "chunk_size = 1000\n\n[gnc.guidance]\nwindow_start_s = 5.0\nwindow_end_s = 2.0",
         "gnc.guidance.window_end_s"),
        ("chunk_size = 1000", 'chunk_size = 1000\n\n[rocket.aero]\nmodel = "linear"\n\n[gnc.control]\n'
         "speeds_mps = [100.0, 300.0]", "gnc.control.speeds_mps"),
        ("chunk_size = 1000", 'chunk_size = 1000\n\n[rocket.aero]\nmodel = "linear"\nlinear.cn_delta = 0.0\n'
         "linear.cm_delta = 0.0\n\n[gnc]", "gnc.servo.limit_deg"),
        ("[dispersions]", '[dispersions]\n"gnc.control.r_weights.0" = { dist = "normal", std = 1.0 }',
         "dispersions.gnc.control.r_weights.0"),
        ("chunk_size = 1000", "chunk_size = 1000\n\n[gnc.servo]\noffset_deg = [0.0, 0.0, -10.5, 0.0]", "gnc.servo.offset_deg"),
        ("chunk_size = 1000", 'chunk_size = 1000\n\n[avionics.gyroscope]\npart = "bmx161"', "avionics.gyroscope"),
        ("chunk_size = 1000", 'chunk_size = 1000\n\n[avionics.gnss]\npart = "bmx160"', "avionics.gnss"),
        ("chunk_size = 1000", 'chunk_size = 1000\n\n[avionics.accelerometer]\npart = "bmx160"\nnoise_density = -1e-3',
         "avionics.accelerometer.noise_density"),
        ("chunk_size = 1000", "chunk_size = 1000\n\n[avionics.gyroscope]\nrate_hz = 30.0", "avionics.gyroscope.rate_hz"),
        ("chunk_size = 1000", "chunk_size = 1000\n\n[avionics.magnetometer]\nrange = [10.0, 2500.0]", "avionics.magnetometer"),
        ("chunk_size = 1000", "chunk_size = 1000\n\n[avionics.barometer]\nlatency_s = 0.03", "avionics.barometer.latency_s"),
        ("chunk_size = 1000", 'chunk_size = 1000\n\n[gnc]\nnavigation = "sensors"', "gnc.navigation"),
        ("[dispersions]", '[avionics]\n\n[dispersions]\n"avionics.gnss.rate_hz" = { dist = "normal", std = 1.0 }',
         "dispersions.avionics.gnss.rate_hz"),
        ("chunk_size = 1000", 'chunk_size = 1000\n\n[avionics]\n\n[gnc]\nnavigation = "filters"\n\n'
         "[gnc.filters.attitude]\ngyro_noise_deg_s = 0.0", "gnc.filters.attitude.gyro_noise_deg_s"),
        ("chunk_size = 1000", 'chunk_size = 1000\n\n[avionics]\n\n[gnc.filters.position]\n'
         "gnss_velocity_std_mps = [50.0, -50.0, 70.0]", "gnc.filters.position.gnss_velocity_std_mps.1"),
        ("chunk_size = 1000", 'chunk_size = 1000\n\n[avionics]\n\n[gnc]\nnavigation = "filters"\n\n'
         '[gnc.filters]\ninitialisation = "pad"', "gnc.filters.initialisation"),
        ("chunk_size = 1000", 'chunk_size = 1000\n\n[avionics]\n\n[gnc]\nnavigation = "filters"\n\n'
         '[gnc.filters]\ninitialisation = "level"', "gnc.filters.initialisation"),
        ("chunk_size = 1000", 'chunk_size = 1000\n\n[gnc]\nnavigation = "filters"', "gnc.navigation"),
        # [environment.magnetic_field]: the truth's model, the IGRF-14's dates, the anomaly and its draws
        ('model = "dipole"', 'model = "wmm"', "environment.magnetic_field.model"),
        ('model = "dipole"', 'model = "igrf"\ndate = "2031-01-01"', "environment.magnetic_field.date"),
        ('model = "dipole"', "date = 1899-12-31", "environment.magnetic_field.date"),  # a TOML date
        ('model = "dipole"', 'date = "18/09/2021"', "environment.magnetic_field.date"),
        ('model = "dipole"', "anomaly_nt = [0.0, 2e5, 0.0]", "environment.magnetic_field.anomaly_nt.1"),
        ('model = "dipole"', "anomaly_nt = [nan, 0.0, 0.0]", "environment.magnetic_field.anomaly_nt.0"),
        ('model = "dipole"', "anomaly_nt = [0.0, 0.0]", "environment.magnetic_field.anomaly_nt"),
        ("[dispersions]", '[dispersions]\n"environment.magnetic_field.anomaly_nt.0" = { dist = "normal", std = 2e4 }',
         "dispersions.environment.magnetic_field.anomaly_nt.0"),
        ("[dispersions]", '[dispersions]\n"environment.magnetic_field.date" = { dist = "normal", std = 1.0 }',
         "dispersions.environment.magnetic_field.date"),
        # The magnetometer's iron spreads; a spread whose draws leave the value's range names the spread
        ("chunk_size = 1000", "chunk_size = 1000\n\n[avionics.magnetometer]\nsoft_iron_std = 0.6",
         "avionics.magnetometer.soft_iron_std"),
        ("chunk_size = 1000", "chunk_size = 1000\n\n[avionics.magnetometer]\nsoft_iron_std = nan",
         "avionics.magnetometer.soft_iron_std"),
        ("chunk_size = 1000", "chunk_size = 1000\n\n[avionics.magnetometer]\nhard_iron_std = -1.0",
         "avionics.magnetometer.hard_iron_std"),
        ("chunk_size = 1000", "chunk_size = 1000\n\n[avionics.magnetometer]\nhard_iron_std = 5e6",
         "avionics.magnetometer.hard_iron_std"),  # 6·std beyond the ±1e7 µT of hard_iron
        ("chunk_size = 1000", "chunk_size = 1000\n\n[avionics.magnetometer]\nsoft_iron_std = 0.5\n"
         "soft_iron = [9.9, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]", "avionics.magnetometer.soft_iron_std"),
        ("chunk_size = 1000", "chunk_size = 1000\n\n[avionics.gyroscope]\nmisalignment_std_deg = 2.0",
         "avionics.gyroscope.misalignment_std_deg"),  # 6·2° beyond the ±10° of misalignment_deg
        ("[dispersions]", '[avionics]\n\n[dispersions]\n"avionics.magnetometer.soft_iron_std" = { dist = "normal", '
         "std = 0.01 }", "dispersions.avionics.magnetometer.soft_iron_std"),
        # The filters' field model and pad initialisation
        ("chunk_size = 1000", 'chunk_size = 1000\n\n[avionics]\n\n[gnc]\nnavigation = "filters"\n\n'
         '[gnc.filters.attitude]\nfield_model = "wmm"', "gnc.filters.attitude.field_model"),
        ("chunk_size = 1000", 'chunk_size = 1000\n\n[avionics]\n\n[gnc]\nnavigation = "filters"\n\n'
         "[gnc.filters]\npad_samples = 2.5", "gnc.filters.pad_samples"),
        ("[dispersions]", '[avionics]\n\n[gnc]\nnavigation = "filters"\n\n[gnc.filters]\ninitialisation = "pad"\n'
         'pad_samples = 20\n\n[dispersions]\n"rocket.motor.ignition_delay_s" = { dist = "uniform", low = 0.1, '
         "high = 1.0 }", "gnc.filters.initialisation"),  # 0.4 s of pad samples, ignition from 0.1 s
        ("[dispersions]", '[avionics]\n\n[gnc]\nnavigation = "filters"\n\n[dispersions]\n'
         '"gnc.filters.pad_samples" = { dist = "uniform", low = 1.0, high = 10.0 }',
         "dispersions.gnc.filters.pad_samples"),
        # The guidance reference, each field set or derived from the campaign
        ("chunk_size = 1000", "chunk_size = 1000\n\n[gnc.guidance]\napogee_m = 0.0", "gnc.guidance.apogee_m"),
        ("chunk_size = 1000", "chunk_size = 1000\n\n[gnc.guidance]\nflight_path_angle_deg = nan",
         "gnc.guidance.flight_path_angle_deg"),
        ("chunk_size = 1000", 'chunk_size = 1000\n\n[gnc.guidance]\nroll_heading_deg = "east"',
         "gnc.guidance.roll_heading_deg"),
        ("chunk_size = 1000", "chunk_size = 1000\n\n[rocket.aero]\nmodel = \"linear\"\n\n[gnc.guidance]\nt0_s = 60.0",
         "gnc.guidance.apogee_m"),  # derived: the nominal flight does not climb after 60 s
        ("[dispersions]", '[gnc]\n\n[dispersions]\n"gnc.guidance.apogee_m" = { dist = "normal", std = 10.0 }',
         "dispersions.gnc.guidance.apogee_m"),
        ("rail_length_m = 4.0", "rail_lenght_m = 4.0", "launch.rail_lenght_m"),  # the misspelling, not the missing key
    ],
    ids=["inf-wind", "nan-thrust-scale", "inf-ignition", "inf-max-time", "clip-excludes-nominal", "newline-name",
         "long-name", "binary-thrust-file", "binary-aero-csv", "elevation-above-90", "negative-mass", "missing-n",
         "unknown-key", "missing-table-file", "unknown-aero-model", "fixed-field-dispersed", "gnc-window-order",
         "gnc-grid-outside-flight", "gnc-no-canard-authority", "gnc-control-dispersed", "gnc-offset-beyond-limit",
         "unknown-part", "part-without-the-sensor", "negative-noise-density", "rate-not-dividing-the-gnc-rate",
         "range-without-zero", "latency-between-ticks", "sensor-navigation-without-avionics", "sensor-rate-dispersed",
         "filter-covariance-zero", "filter-covariance-negative", "pad-initialisation-without-pad-time",
         "level-initialisation-without-pad-time", "filters-without-avionics", "unknown-field-model",
         "igrf-date-after-2030", "toml-date-before-1900",
         "date-not-iso", "anomaly-beyond-1e5-nt", "anomaly-nan", "anomaly-two-axes", "anomaly-draws-out-of-range",
         "date-dispersed", "soft-iron-spread-above-0.5", "soft-iron-spread-nan", "negative-hard-iron-spread",
         "hard-iron-spread-draws-out-of-range", "soft-iron-spread-draws-out-of-range",
         "misalignment-spread-draws-out-of-range", "soft-iron-spread-dispersed", "unknown-filter-field-model",
         "pad-samples-not-whole", "pad-time-against-dispersed-ignition", "pad-samples-dispersed", "apogee-zero",
         "flight-path-angle-nan", "roll-heading-text", "derived-apogee-after-the-climb", "apogee-dispersed",
         "misspelt-required-key"],
)  # fmt: skip
def test_cli_run_refuses_with_one_line_and_writes_nothing(tmp_path, capsys, old, new, field):
    assert old in NOMINAL, old
    (tmp_path / "binary.eng").write_bytes(BINARY)
    (tmp_path / "binary.csv").write_bytes(BINARY)
    campaign = tmp_path / "bad.toml"
    campaign.write_text(NOMINAL.replace(old, new, 1))
    before = set(tmp_path.iterdir())
    assert main(["run", str(campaign), "--out", str(tmp_path / "x.h5")]) == 2
    lines = capsys.readouterr().err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("rocketmc: error:") and f": {field}: " in lines[0], lines
    assert len(lines[0]) < 400, lines[0]  # the 10 000-character name is not echoed
    assert set(tmp_path.iterdir()) == before  # neither x.h5 nor x.h5.partial/


def leaf_paths(raw: dict) -> list[tuple[str, ...]]:
    """The keys to every numeric leaf of a campaign's tables (``flatten_numbers``' dotted paths, each
    dispersion's dotted name kept whole)."""
    paths = [tuple(p.split(".")) for p in flatten_numbers({k: v for k, v in raw.items() if k != "dispersions"})]
    for name, dispersion in raw["dispersions"].items():
        paths += [("dispersions", name, *p.split(".")) for p in flatten_numbers(dispersion)]
    return paths


LEAVES = leaf_paths(EXPANDED)
EDGE_VALUES = [math.inf, -math.inf, math.nan, 1e308, -1e308, 5e-324, 0.0, -1.0, 1e6, -1e6]


@settings(max_examples=300, deadline=None, database=None)  # ~3 ms a campaign: ~1 s; no example database
@given(
    keys=st.sampled_from(LEAVES),
    value=st.one_of(st.sampled_from(EDGE_VALUES), st.floats(), st.floats(-1e4, 1e4), st.integers(-10**20, 10**20)),
)
def test_any_number_anywhere_loads_finite_or_names_the_field(keys, value):
    """One numeric leaf of the (valid) nominal campaign replaced: it loads with every number finite, or the
    ConfigError names a field of the edited section (or a dispersion, whose draws depend on the nominal)."""
    try:
        campaign = campaign_from_dict(replaced(EXPANDED, keys, value), CAMPAIGNS)
    except ConfigError as e:
        message = str(e)
        assert "\n" not in message and FIELD_PREFIX.match(message), message
        assert re.match("[a-z_]+", message).group() in (keys[0], "dispersions"), (keys, message)
    else:
        numbers = {**flatten_numbers(campaign.config.model_dump()), **campaign.nominal}
        assert all(math.isfinite(x) for x in numbers.values()), (keys, value)


GNC = {
    **replaced(EXPANDED, "rocket.aero.model", "linear"),
    "gnc": {"servo": {}, "guidance": {}, "control": {},
            "filters": {"pad_samples": 500, "attitude": {"gyro_noise_deg_s": 60.0, "field_direction_std": 2.0},
                        "position": {"gnss_after_s": 10.5, "gnss_velocity_std_mps": [50.0, 50.0, 70.0],
                                     "altitude_std_m": 5.0}}},
}  # fmt: skip
"""The expanded nominal campaign with the thesis's closed loop on the thesis's linear model (its gains
designed in ~0.3 s), a few of the navigation filters' numbers spelt out (for the fuzz below); every case below
edits it once."""


def test_gnc_base_is_valid():
    assert campaign_from_dict(GNC, CAMPAIGNS).gnc_schedule is not None


@pytest.mark.parametrize(
    ("path", "value", "message_start"),
    [
        ("gnc.guidance.window_end_s", 0.5,
         "gnc.guidance.window_end_s: the window must end after it starts (window_start_s = 1.0) (got 0.5)"),
        ("gnc.guidance.window_start_s", -1.0, "gnc.guidance.window_start_s: Input should be greater than or equal to 0"),
        ("gnc.guidance.flight_path_angle_deg", 90.0, "gnc.guidance.flight_path_angle_deg: Input should be less than 90"),
        ("gnc.guidance.apogee_m", -5.0, "gnc.guidance.apogee_m: Input should be greater than 0 (got -5.0)"),
        ("gnc.guidance.apogee_m", "high", "gnc.guidance.apogee_m: Input should be a valid number"),
        ("gnc.guidance.roll_heading_deg", 1000.0, "gnc.guidance.roll_heading_deg: Input should be less than or equal to 720"),
        ("gnc.guidance.t0_s", 60.0, "gnc.guidance.apogee_m: the nominal flight (a point-mass estimate) does not climb"),
        ("gnc.guidance.integrator_gain", [500.0, 500.0, 500.0],
         "gnc.guidance.integrator_gain: LQI design at speed 200 m/s"),
        ("gnc.control.q_weights", [0.0, 0.0, 0.0, -5.0, 5.0, 0.0, 0.0, 0.0, 10.0, 10.0, 10.0],
         "gnc.control.q_weights.3: Input should be greater than or equal to 0 (got -5.0)"),
        ("gnc.control.q_weights", [5.0] * 10, "gnc.control.q_weights: List should have at least 11 items"),
        ("gnc.control.r_weights", [100.0, 0.0, 100.0], "gnc.control.r_weights.1: Input should be greater than 0 (got 0.0)"),
        ("gnc.control.speeds_mps", [20.0, 100.0, 100.0, 300.0],
         "gnc.control.speeds_mps: the grid must be strictly increasing, got [20.0, 100.0, 100.0, 300.0]"),
        ("gnc.control.altitudes_m", [1000.0, 0.0], "gnc.control.altitudes_m: the grid must be strictly increasing"),
        ("gnc.control.speeds_mps", [0.0, 300.0], "gnc.control.speeds_mps.0: Input should be greater than 0"),
        ("gnc.control.altitudes_m", [], "gnc.control.altitudes_m: List should have at least 1 item"),
        ("gnc.control.discretisation", "tustin", "gnc.control.discretisation: Input should be 'zoh' or 'euler'"),
        ("gnc.servo.limit_deg", 0.0, "gnc.servo.limit_deg: Input should be greater than 0 (got 0.0)"),
        ("gnc.servo.limit_deg", 90.0, "gnc.servo.limit_deg: Input should be less than or equal to 45"),
        ("gnc.servo.time_constant_s", 0.0, "gnc.servo.time_constant_s: Input should be greater than 0"),
        ("gnc.servo.rate_limit_deg_s", -60.0, "gnc.servo.rate_limit_deg_s: Input should be greater than 0"),
        ("gnc.servo.offset_deg", [0.0, 10.0, 0.0, 0.0],
         "gnc.servo.offset_deg: each offset must be smaller in magnitude than limit_deg (10.0), got [0.0, 10.0, 0.0, 0.0]"),
        ("gnc.servo.offset_deg", [0.0, 0.0, 0.0], "gnc.servo.offset_deg: List should have at least 4 items"),
        ("gnc.navigation", "ekf", "gnc.navigation: Input should be 'truth'"),
        ("gnc.filters.attitude.field_direction_std", -2.0,
         "gnc.filters.attitude.field_direction_std: Input should be greater than 0 (got -2.0)"),
        ("gnc.filters.position.initial_velocity_std_mps", 0.0,
         "gnc.filters.position.initial_velocity_std_mps: Input should be greater than 0 (got 0.0)"),
        ("gnc.filters.position.gnss", "vertical", "gnc.filters.position.gnss: Input should be 'all' or 'horizontal'"),
        ("gnc.filters.pad_samples", 0, "gnc.filters.pad_samples: Input should be greater than or equal to 1"),
        ("gnc.filters.position.altitude_gate", -9.0,
         "gnc.filters.position.altitude_gate: Input should be greater than 0 (got -9.0)"),
        ("gnc.filters.attitude.field_gate", 1e5, "gnc.filters.attitude.field_gate: Input should be less than or equal to"),
        ("gnc.filters.position.gnss_gate", "tight", "gnc.filters.position.gnss_gate: Input should be a valid number"),
        ("gnc.filters.initialisation", "triad", "gnc.filters.initialisation: Input should be 'rail', 'pad' or 'level'"),
    ],
)  # fmt: skip
def test_bad_gnc_fields_are_refused_naming_the_field(path, value, message_start):
    message = refusal(replaced(GNC, path, value))
    assert message.startswith(message_start), message


@pytest.mark.parametrize(
    ("path", "grid", "words"),
    [
        ("gnc.control.speeds_mps", [100.0, 300.0],
         "gnc.control.speeds_mps: the grid spans 100 to 300 m/s, the nominal flight 62 to 183 m/s in the guidance "
         "window (1 to 10 s after liftoff; a point-mass estimate): extend the grid"),
        ("gnc.control.speeds_mps", [20.0, 150.0], "the nominal flight 62 to 183 m/s"),
        ("gnc.control.altitudes_m", [0.0, 500.0], "gnc.control.altitudes_m: the grid spans 0 to 500 m above the pad, "
         "the nominal flight 30 to 1221 m above the pad"),
        ("gnc.control.altitudes_m", [100.0, 2000.0], "the nominal flight 30 to 1221 m above the pad"),
    ],
)  # fmt: skip
def test_a_grid_outside_the_flight_is_refused(path, grid, words):
    """Lynx flies 62-183 m/s and 30-1221 m above the pad 1-10 s after liftoff (estimated): a grid missing
    either end is refused."""
    message = refusal(replaced(GNC, path, grid))
    assert message.startswith(path) and words in message, message


def test_one_altitude_designs_for_every_altitude():
    """A one-point altitude grid is not checked against the flight: its gains serve every altitude."""
    campaign = campaign_from_dict(replaced(GNC, "gnc.control.altitudes_m", [5000.0]), CAMPAIGNS)
    assert campaign.gnc_schedule.altitudes.tolist() == [5000.0 + EXPANDED["site"]["altitude_m"]]


def test_a_window_the_flight_misses_is_refused():
    raw = replaced(replaced(GNC, "gnc.guidance.window_start_s", 200.0), "gnc.guidance.window_end_s", 300.0)
    assert refusal(raw) == ("gnc.guidance.window_start_s: the nominal flight (a point-mass estimate) is not in the air "
                            "from 200 to 300 s after liftoff")  # fmt: skip


@pytest.mark.filterwarnings("ignore::RuntimeWarning")  # scipy, on the singular pencil
def test_a_design_point_without_control_authority_is_refused():
    """Canards with no pitch and yaw authority (CN_δ = Cm_δ = 0): they trim the rocket to 0°, refused before the
    design (whose DARE has no stabilising solution then: the pitch and yaw integrators on the unit circle)."""
    raw = replaced(replaced(GNC, "rocket.aero.linear.cn_delta", 0.0), "rocket.aero.linear.cm_delta", 0.0)
    message = refusal(raw)
    assert message.startswith("gnc.servo.limit_deg: the canards at 10° trim the rocket to 0° of angle of attack"), message


def test_gnc_needs_four_canards():
    """The as-flown Lynx (3 fins, no canards, DATCOM table; ~5 s to linearise) cannot carry the controller."""
    raw = {**GNC, "rocket": {"preset": "lynx_2021"}}
    assert refusal(raw).startswith("gnc: the controller steers four canards; this rocket's aerodynamic model has 0")


@pytest.mark.parametrize(
    ("path", "dispersion", "message_start"),
    [
        ("gnc.control.r_weights.0", {"dist": "normal", "std": 1.0}, "dispersions.gnc.control.r_weights.0: fixed for the "
         "whole campaign (guidance, the LQI gains and the navigation filters are set once, when it loads); only the servos"),
        ("gnc.guidance.window_start_s", {"dist": "uniform", "low": 1.0, "high": 3.5},
         "dispersions.gnc.guidance.window_start_s: fixed for the whole campaign"),
        ("gnc.filters.attitude.field_direction_std", {"dist": "normal", "std": 0.5},
         "dispersions.gnc.filters.attitude.field_direction_std: fixed for the whole campaign"),
        ("gnc.servo.limit_deg", {"dist": "normal", "std": 2.0}, "dispersions.gnc.servo.limit_deg: draws a value -2.0 "
         "(mean − 6·std; clip it with low) that is out of range: gnc.servo.limit_deg: Input should be greater than 0"),
        ("gnc.servo.offset_deg.2", {"dist": "uniform", "low": -12.0, "high": 0.0},
         "dispersions.gnc.servo.offset_deg.2: draws a value -12.0 that is out of range: gnc.servo.offset_deg: each "
         "offset must be smaller in magnitude than limit_deg (10.0)"),
        ("gnc.servo.rate_limit_deg_s", {"dist": "normal", "std": 10.0},
         "dispersions.gnc.servo.rate_limit_deg_s: not a dispersible number"),  # None: no slew limit to disperse
    ],
)  # fmt: skip
def test_gnc_dispersions(path, dispersion, message_start):
    """Only the servos are dispersible, and every value they can draw is checked like any other."""
    message = refusal({**GNC, "dispersions": {**GNC["dispersions"], path: dispersion}})
    assert message.startswith(message_start), message


def test_servo_dispersions_load():
    dispersions = {"gnc.servo.time_constant_s": {"dist": "normal", "std": 0.005},
                   "gnc.servo.offset_deg.0": {"dist": "normal", "std": 0.5}}  # fmt: skip
    campaign = campaign_from_dict({**GNC, "dispersions": {**GNC["dispersions"], **dispersions}}, CAMPAIGNS)
    assert campaign.nominal["gnc.servo.time_constant_s"] == 0.0769 and campaign.nominal["gnc.servo.offset_deg.0"] == 0.0


GNC_EXPANDED = {**GNC, "dispersions": {}, "gnc": GncConfig(
    servo=ServoConfig(rate_limit_deg_s=300.0), guidance=GuidanceConfig(heading_deg=130.0)
).model_dump()}  # fmt: skip
"""The [gnc] campaign with every field of its section written out (the servo's slew limit and the heading too)."""
GNC_LEAVES = [keys for keys in leaf_paths(GNC_EXPANDED) if keys[0] == "gnc"]


@pytest.mark.filterwarnings("ignore::RuntimeWarning")  # scipy on the extreme plants of some draws (overflow, NaN)
@settings(max_examples=40, deadline=None, database=None)  # ~0.3 s a valid campaign (its gains designed): ~10 s
@given(keys=st.sampled_from(GNC_LEAVES), value=st.one_of(st.sampled_from(EDGE_VALUES), st.floats(), st.floats(-1e4, 1e4)))
def test_any_gnc_number_loads_finite_or_names_the_field(keys, value):
    """One number of the [gnc] section replaced: it loads with finite gains, or the one-line ConfigError
    names a field of [gnc]."""
    try:
        campaign = campaign_from_dict(replaced(GNC_EXPANDED, keys, value), CAMPAIGNS)
    except ConfigError as e:
        message = str(e)
        assert "\n" not in message and FIELD_PREFIX.match(message) and message.startswith("gnc"), (keys, message)
    else:
        assert np.all(np.isfinite(campaign.gnc_schedule.gains)), (keys, value)

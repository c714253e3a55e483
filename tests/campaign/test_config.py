"""Campaign validation: each kind of bad input is one line naming the field."""

import copy
import re
import tomllib
from pathlib import Path

import jax
import numpy as np
import pytest

from rocketmc.campaign import ConfigError, campaign_from_dict, load_campaign, parse_campaign, with_overrides
from rocketmc.campaign.checks import motor_warnings
from rocketmc.campaign.fingerprint import setup
from rocketmc.dynamics.motor_library import casing_inertia_kgm2, estimated_grain, find_motor
from rocketmc.campaign.schema import GncConfig
from rocketmc.campaign.model import nominal_params

CAMPAIGNS = Path(__file__).parents[2] / "campaigns"
NOMINAL = (CAMPAIGNS / "lynx_nominal.toml").read_text()


def edited(old: str, new: str) -> str:
    assert old in NOMINAL, old
    return NOMINAL.replace(old, new, 1)


ROCKETS = Path(__file__).parents[2] / "src" / "rocketmc" / "data" / "rockets"
MOTORS = ROCKETS.parent / "motors"
# Numbers a campaign may leave out, by dotted path with list indices as '*', and their defaults.
DEFAULTS = {
    "rocket.nose_position_m": 0.0, "rocket.canopy_roll_damping": -5.0, "rocket.motor.thrust_scale": 1.0,
    "rocket.motor.ignition_delay_s": 0.0, "rocket.motor.dry_mass_kg": 0.0, "rocket.motor.dry_inertia_kgm2.*": 0.0,
    "rocket.aero.drag_scale": 1.0, "rocket.aero.cl0": 0.0, "rocket.geometry.fins.*.cant_deg": 0.0,
    "rocket.geometry.fins.*.first_panel_deg": 0.0, "rocket.geometry.fins.*.thickness_m": 0.005,
    "rocket.geometry.canards.cant_deg": 0.0, "rocket.geometry.canards.first_panel_deg": 0.0,
    "rocket.parachutes.*.opening_time_s": 0.0, "environment.wind.speed_scale": 1.0,
    "environment.atmosphere.wind_rotation_deg": 0.0, "environment.atmosphere.wind_scale": 1.0,
    "environment.magnetic_field.anomaly_nt.*": 0.0,
}  # fmt: skip
PARTS = ROCKETS.parent / "sensors"
SENSOR_DEFAULTS = {
    "bias.*": 0.0, "bias_std.*": 0.0, "bias_walk": 0.0, "scale_factor.*": 0.0, "scale_factor_std": 0.0, "cross_axis.*": 0.0,
    "cross_axis_std": 0.0, "misalignment_deg.*": 0.0, "misalignment_std_deg": 0.0, "mounting_deg.*": 0.0,
    "hard_iron.*": 0.0, "hard_iron_std": 0.0, "soft_iron_std": 0.0, "latency_s": 0.0, "sinusoid_amplitude_m.*": 0.0,
    "sinusoid_frequency_hz": 0.0, "sinusoid_phase_deg.*": 0.0, "first_fix_s": 0.0, "vibration_per_kpa.*": 0.0,
}  # fmt: skip
"""Numbers a sensor's part and table may leave out (by the field's path in the sensor's table) and their defaults;
the soft-iron matrix defaults to the identity."""


def _avionics(avionics: dict) -> dict:
    """The [avionics] table with each sensor's part (data/sensors/<part>.toml, read here with tomllib) under
    the sensor's own table: its own part, else the section's if that part has the sensor, else the thesis's."""
    sensors = ("accelerometer", "gyroscope", "magnetometer", "barometer", "gnss", "canard_feedback")
    section = tomllib.loads((PARTS / f"{avionics.get('part', 'thesis')}.toml").read_text())
    merged = {}
    for sensor in sensors:
        own = avionics.get(sensor, {})
        name = own.get("part", avionics.get("part", "thesis") if sensor in section else "thesis")
        part = tomllib.loads((PARTS / f"{name}.toml").read_text())[sensor]
        if "noise_density" in own or "noise_std" in own:  # the table's own kind of white noise replaces the part's
            part = {k: v for k, v in part.items() if k not in ("noise_density", "noise_std")}
        merged[sensor] = {**part, **own}
    return merged


def _sensor_default(key: str):
    """The default of ``avionics.<sensor>.<field>...`` numbers a part leaves out, or None."""
    field = re.sub(r"\.\d+$", ".*", key.split(".", 2)[2])
    if field == "soft_iron.*":
        return [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0][int(key.rsplit(".", 1)[1])]
    return SENSOR_DEFAULTS.get(field)


def _flat(tree, prefix=""):
    """{dotted path: value} of a TOML tree, list items by index ("layers.0.speed_mps")."""
    if isinstance(tree, dict):
        return {k: v for key, sub in tree.items() for k, v in _flat(sub, f"{prefix}{key}.").items()}
    if isinstance(tree, list) and tree and all(isinstance(x, dict | list) for x in tree):
        return {k: v for i, sub in enumerate(tree) for k, v in _flat(sub, f"{prefix}{i}.").items()}
    if isinstance(tree, list):
        return {f"{prefix}{i}": x for i, x in enumerate(tree)} or {prefix[:-1]: []}
    return {prefix[:-1]: tree}


def _over(base, override):
    """``base`` with ``override`` on top, tables merged key by key, anything else replaced."""
    merged = dict(base)
    for key, value in override.items():
        both_tables = isinstance(value, dict) and isinstance(base.get(key), dict)
        merged[key] = _over(base[key], value) if both_tables else value
    return merged


def _written(path):
    """A campaign file's tables over those of the campaign it extends (beside it), read with tomllib."""
    data = tomllib.loads(path.read_text())
    base = data.pop("extends", None)
    return data if base is None else _over(_written(path.parent / base), data)


def _number(x):
    return isinstance(x, int | float) and not isinstance(x, bool)


@pytest.mark.parametrize("path", sorted(CAMPAIGNS.glob("*.toml")), ids=lambda p: p.name)
def test_shipped_campaigns_load(path):
    """What the loader holds is what the campaign file, the campaigns it extends and its preset say, read here with tomllib:
    every number of the rocket (the preset under the file's overrides, lists replaced whole),
    launch, environment and gnc tables is its nominal value, and the only other nominal values are
    the schema's defaults listed in DEFAULTS (and GncConfig's, with a [gnc] section); name, N, seed,
    site, simulation and the dispersions are the file's; a RASP thrust curve is the file's points
    after the implicit (0, 0)."""
    data = _written(path)
    campaign = load_campaign(path)
    config = campaign.config
    rocket = dict(data["rocket"])
    preset = rocket.pop("preset", None)
    if preset is not None:
        rocket = _over(tomllib.loads((ROCKETS / f"{preset}.toml").read_text()), rocket)
    written = {"rocket": rocket, "launch": data["launch"], "environment": data["environment"], "gnc": data.get("gnc", {}),
               "avionics": _avionics(data["avionics"]) if "avionics" in data else {}}  # fmt: skip
    numbers = {k: v for k, v in _flat(written).items() if _number(v)}
    assert {k: campaign.nominal.get(k) for k in numbers} == numbers
    defaults = {k: v for k, v in campaign.nominal.items() if k not in numbers}
    gnc_defaults = _flat({"gnc": GncConfig().model_dump()}) if "gnc" in data else {}
    expected = {k: _sensor_default(k) if k.startswith("avionics.") else
                DEFAULTS.get(re.sub(r"\.\d+(?=\.|$)", ".*", k), gnc_defaults.get(k)) for k in defaults}  # fmt: skip
    assert expected == defaults
    loaded = _flat(config.model_dump())
    for key, value in _flat(written).items():  # the words too: model names, files, parachute names
        if not _number(value):
            assert loaded[key] == value, key

    assert (config.name, config.n_realizations, config.seed) == (data["name"], data["n_realizations"], data["seed"])
    assert config.site.model_dump() == data["site"]
    simulation = config.simulation.model_dump()
    assert {k: simulation[k] for k in data.get("simulation", {})} == data.get("simulation", {})
    # the file's dispersions, after those its sensors' per-flight spreads imply (normal, about the nominal value)
    upper = {"cross_axis": range(6), "soft_iron": (0, 1, 2, 4, 5, 8)}  # the soft-iron matrix's upper triangle
    spreads = {f"avionics.{sensor}.{target}.{i}": std
               for sensor, table in written["avionics"].items() for spread, target in
               (("bias_std", "bias"), ("scale_factor_std", "scale_factor"), ("cross_axis_std", "cross_axis"),
                ("misalignment_std_deg", "misalignment_deg"), ("hard_iron_std", "hard_iron"),
                ("soft_iron_std", "soft_iron")) if spread in table
               for i, std in (enumerate(table[spread]) if isinstance(table[spread], list) else
                              ((i, table[spread]) for i in upper.get(target, range(3)))) if std > 0}  # fmt: skip
    assert list(config.dispersions) == [*spreads, *(k for k in data.get("dispersions", {}) if k not in spreads)]
    for key, std in spreads.items():
        assert config.dispersions[key].model_dump(exclude_none=True) == {"dist": "normal", "std": std}, key
    for key, given in data.get("dispersions", {}).items():
        assert {k: v for k, v in config.dispersions[key].model_dump().items() if v is not None} == given, key
        assert key in campaign.nominal

    curve = MOTORS / rocket["motor"]["thrust_curve"]
    if curve.suffix == ".eng":
        rows = [line.split() for line in curve.read_text().splitlines() if line.strip() and not line.startswith(";")]
        points = np.array([[float(x) for x in row] for row in rows[1:]])  # after the header line
        np.testing.assert_array_equal(campaign.thrust_time_s, np.r_[0.0, points[:, 0]])
        np.testing.assert_array_equal(campaign.thrust_n, np.r_[0.0, points[:, 1]])


def test_preset_and_override():
    campaign = parse_campaign(edited('preset = "lynx"', 'preset = "lynx"\ndry_mass_kg = 20.0'))
    assert campaign.nominal["rocket.dry_mass_kg"] == 20.0
    assert campaign.nominal["rocket.aero.linear.cn_alpha"] == pytest.approx(24.0744)  # untouched preset value


def test_a_campaign_extends_another(tmp_path):
    """A variant of a few lines: its tables laid over the base's key by key, through a chain of two, is the base
    edited by hand; an array of tables (the wind layers) replaces the base's whole, not layer by layer."""
    (tmp_path / "base.toml").write_text(NOMINAL)
    (tmp_path / "heavy.toml").write_text('extends = "base.toml"\nname = "heavy"\n[rocket]\ndry_mass_kg = 20.0\n')
    (tmp_path / "steep.toml").write_text('extends = "heavy.toml"\nname = "steep"\n[launch]\nelevation_deg = 85.0\n')
    by_hand = edited('name = "lynx_nominal"', 'name = "steep"').replace(
        'preset = "lynx"', 'preset = "lynx"\ndry_mass_kg = 20.0').replace("elevation_deg = 84.0", "elevation_deg = 85.0")
    assert load_campaign(tmp_path / "steep.toml").config == parse_campaign(by_hand).config
    layers = "".join(f"[[environment.wind.layers]]\nspeed_mps = {v}\nfrom_deg = 90.0\n{thickness}\n"
                     for v, thickness in ((1.0, "thickness_m = 100.0"), (2.0, "thickness_m = 50.0"), (3.0, "")))
    (tmp_path / "east.toml").write_text(f'extends = "base.toml"\n{layers}')
    east = load_campaign(tmp_path / "east.toml").config.environment.wind.layers
    assert [(layer.speed_mps, layer.from_deg, layer.thickness_m) for layer in east] == [
        (1.0, 90.0, 100.0), (2.0, 90.0, 50.0), (3.0, 90.0, None)]  # fmt: skip
    (tmp_path / "east.toml").write_text('extends = "base.toml"\n[[environment.wind.layers]]\nspeed_mps = 1.0\n'
                                        "from_deg = 90.0\n[[environment.wind.layers]]\nspeed_mps = 2.0\nfrom_deg = 90.0\n")
    with pytest.raises(ConfigError, match="layers.0.thickness_m is required"):  # not the base's first layer's 275 m
        load_campaign(tmp_path / "east.toml")


@pytest.mark.parametrize(("files", "words"), [
    ({"a.toml": 'extends = "b.toml"', "b.toml": 'extends = "a.toml"'}, "extends: 'b.toml' → 'a.toml' → 'b.toml' is a circle"),
    ({"a.toml": 'extends = "nowhere.toml"'}, "extends: file not found: 'nowhere.toml'"),
    ({"a.toml": "extends = 3"}, "extends: expected a campaign file name"),
    ({"a.toml": 'extends = "b.toml"', "b.toml": "name = "}, "extends: 'b.toml' is not valid TOML"),
])  # fmt: skip
def test_a_bad_extends_is_one_line(tmp_path, files, words):
    for name, text in files.items():
        (tmp_path / name).write_text(text + "\n")
    with pytest.raises(ConfigError, match=f"^{re.escape(words)}"):
        load_campaign(tmp_path / "a.toml")


def test_a_rocket_from_a_file_of_the_users(tmp_path):
    """``rocket.preset = "my_rocket.toml"``: a [rocket] table's keys in a file beside the campaign, overridable as a
    built-in preset's; the Lynx's preset copied there gives the built-in preset's campaign."""
    (tmp_path / "my_rocket.toml").write_text((ROCKETS / "lynx.toml").read_text())
    (tmp_path / "c.toml").write_text(edited('preset = "lynx"', 'preset = "my_rocket.toml"\ndry_mass_kg = 20.0'))
    mine = load_campaign(tmp_path / "c.toml")
    assert mine.config == parse_campaign(edited('preset = "lynx"', 'preset = "lynx"\ndry_mass_kg = 20.0')).config
    (tmp_path / "c.toml").write_text(edited('preset = "lynx"', 'preset = "their_rocket.toml"'))
    with pytest.raises(ConfigError, match="^rocket.preset: file not found: 'their_rocket.toml'"):
        load_campaign(tmp_path / "c.toml")


@pytest.mark.parametrize(
    ("text", "field", "words"),
    [
        (edited("n_realizations = 1000\n", ""), "n_realizations", "missing"),
        (edited("seed = 2021", 'seed = "2021"'), "seed", "integer"),
        (edited("rail_length_m = 4.0", "rail_length_m = 4.0\nrail_lenght_m = 5.0"), "launch.rail_lenght_m", "unknown key"),
        (edited('preset = "lynx"', 'preset = "lynx"\ndry_mass_kg = -1.0'), "rocket.dry_mass_kg", "greater than or equal to 0.001"),
        (edited("elevation_deg = 84.0", "elevation_deg = 95.0"), "launch.elevation_deg", "less than or equal to 90"),
        (edited("speed_mps = 7.5", "speed_mps = -7.5"), "environment.wind.layers.0.speed_mps", "greater than or equal to 0"),
        (edited('preset = "lynx"', 'preset = "lynks"'), "rocket.preset", "unknown preset"),
        (edited('preset = "lynx"', 'preset = "lynx"\nmotor.thrust_curve = "nope.eng"'), "rocket.motor.thrust_curve", "not found"),
        (edited('preset = "lynx"', 'preset = "lynx"\nmotor.isp_s = 150.0'), "rocket.motor.isp_s", "disagrees"),
        (edited("[dispersions]", '[dispersions]\n"rocket.mass" = { dist = "normal", std = 1.0 }'), "dispersions.rocket.mass", "not a dispersible"),
        (edited("[dispersions]", '[dispersions]\n"launch.rail_length_m" = { dist = "uniform", low = -1.0, high = 5.0 }'), "dispersions.launch.rail_length_m", "out of range"),
        (edited("[dispersions]", '[dispersions]\n"launch.rail_length_m" = { dist = "uniform", low = 4.0 }'), "dispersions.launch.rail_length_m", "needs 'high'"),
        (edited("[dispersions]", '[dispersions]\n"launch.rail_length_m" = { dist = "gauss", std = 1.0 }'), "dispersions.launch.rail_length_m.dist", "normal"),
        (NOMINAL + "\n[[[", "", "not valid TOML"),
        (edited("severity = 1.0", "severity = 4.0"), "environment.turbulence.severity", "less than or equal to 3"),
        (edited("values = [0.0, 1.0, 2.0, 3.0]", "values = [0.0, 1.0, 2.0, 5.0]"), "dispersions.environment.turbulence.severity", "out of range"),
        (edited("[environment.turbulence]", '[environment.wind]\nexponent = 0.2\n\n[environment.turbulence]'), "environment.wind", "'exponent' does not apply to the 'layers' wind model"),
        (edited('preset = "lynx"', 'preset = "lynx"\nairbrakes = { time_s = [0.0, 4.0], delta_ca = [0.0, 0.5, 0.2] }'), "rocket.airbrakes", "same length"),
        (edited("rail_length_m = 4.0", "rail_lenght_m = 4.0"), "launch.rail_lenght_m", "unknown key (did you mean 'rail_length_m'?)"),
        (edited("rail_length_m = 4.0", "rail_length = 4.0"), "launch.rail_length", "unknown key (did you mean 'rail_length_m'?)"),
        (edited("rail_length_m = 4.0", "xyz = 4.0"), "launch.rail_length_m", "missing (required)"),
    ],
    ids=["missing", "wrong-type", "unknown-key", "negative-mass", "elevation>90", "negative-wind", "preset",
         "thrust-file", "isp", "dispersion-path", "dispersion-range", "dispersion-params", "dispersion-kind", "toml",
         "severity", "severity-draw", "wind-key", "airbrakes", "misspelt-required-key", "required-key-without-unit",
         "unknown-key-beside-a-missing-one"],
)  # fmt: skip
def test_bad_input_names_the_field(text, field, words):
    with pytest.raises(ConfigError) as info:
        parse_campaign(text, CAMPAIGNS)
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith(field), message
    assert words in message, message


def numeric_leaves(tree):
    """The leaves of a FlightParams, random keys as their integer data."""
    as_data = lambda x: jax.random.key_data(x) if jax.dtypes.issubdtype(x.dtype, jax.dtypes.prng_key) else x  # noqa: E731
    return [as_data(x) for x in jax.tree_util.tree_leaves(tree)]


def test_tail_to_nose_positions_give_the_same_flight():
    """The Lynx with every position rewritten tail-to-nose from an origin 3 m aft of the nose tip
    (RocketPy's convention) gives the same flight parameters: p' = 3 − p for every position."""
    origin = 3.0
    flipped = """
coordinate_system = "tail_to_nose"
nose_position_m = 3.0
reference_point_m = 1.67
dry_cg_m = 1.67
rear_lug_m = 1.262
motor = { nozzle_m = 0.52 }

[[rocket.parachutes]]
name = "drogue"
cd = 0.9
area_m2 = 0.6
delay_s = 0.5
opening_time_s = 0.2
attach_m = 2.28

[[rocket.parachutes]]
name = "main"
cd = 0.9
area_m2 = 10.6
deploy_altitude_m = 350.0
delay_s = 1.0
opening_time_s = 0.7
attach_m = 2.28

[rocket.geometry]
fins = [{ count = 4, root_chord_m = 0.35, tip_chord_m = 0.12, span_m = 0.12, sweep_m = 0.23, position_m = 0.855, thickness_m = 0.003 }]
canards = { count = 4, root_chord_m = 0.150, tip_chord_m = 0.080, span_m = 0.080, sweep_m = 0.035, position_m = 2.675, thickness_m = 0.005 }

"""
    assert origin - 1.33 == pytest.approx(1.67) and origin - 2.145 == pytest.approx(0.855)
    reference = nominal_params(parse_campaign(NOMINAL))
    campaign = parse_campaign(edited('preset = "lynx"', 'preset = "lynx"' + flipped))
    for a, b in zip(numeric_leaves(nominal_params(campaign)), numeric_leaves(reference)):
        np.testing.assert_allclose(a, b, rtol=1e-12, atol=1e-12)  # positions differ by float rounding only


def test_motor_dry_mass_joins_the_airframe_by_the_parallel_axis_theorem():
    """2 kg of the Lynx's dry mass moved into the motor's casing 0.9 m aft of the dry CG, with the
    airframe's CG moved forward to keep the total: same mass and CG; inertia = the airframe's and
    the casing's own plus the parallel-axis terms m_a·a² + m_m·b²."""

    reference = nominal_params(parse_campaign(NOMINAL)).rocket
    m_total, m_motor, arm = 18.362, 2.0, 0.9
    shift = m_motor * arm / (m_total - m_motor)  # airframe CG forward of 1.33 m
    split = nominal_params(parse_campaign(edited(
        'preset = "lynx"',
        f'preset = "lynx"\ndry_mass_kg = {m_total - m_motor}\ndry_cg_m = {1.33 - shift}\n'
        f'motor = {{ dry_mass_kg = {m_motor}, dry_cg_m = {1.33 + arm}, dry_inertia_kgm2 = [0.01, 0.2] }}',
    ))).rocket  # fmt: skip
    assert float(split.dry_mass_kg) == pytest.approx(m_total, rel=1e-14)
    assert float(split.dry_cg_x_m) == pytest.approx(float(reference.dry_cg_x_m), abs=1e-12)
    parallel = (m_total - m_motor) * shift**2 + m_motor * arm**2
    assert float(split.dry_iyy_kgm2) == pytest.approx(6.436 + 0.2 + parallel, rel=1e-12)
    assert float(split.dry_ixx_kgm2) == pytest.approx(0.06 + 0.01, rel=1e-12)


def with_wind(wind: dict, **environment) -> dict:
    """The nominal campaign's tables with another mean wind and no wind dispersions."""
    raw = tomllib.loads(NOMINAL)
    raw["environment"] = {"wind": wind, **environment}
    raw["dispersions"] = {k: v for k, v in raw["dispersions"].items() if not k.startswith("environment.")}
    return raw


def test_wind_models_of_a_campaign(tmp_path):
    """constant, power_law and profile campaigns fly the wind their keys describe (from the west, to the east)."""
    constant = nominal_params(campaign_from_dict(with_wind({"model": "constant", "speed_mps": 6.0, "from_deg": 270.0})))
    assert float(constant.environment.wind.velocity_n(3000.0).y) == pytest.approx(6.0, rel=1e-15)
    power = nominal_params(campaign_from_dict(with_wind({"model": "power_law", "speed_mps": 6.0, "from_deg": 270.0})))
    assert float(power.environment.wind.velocity_n(640.0).y) == pytest.approx(6.0 * 64.0 ** (1 / 7), rel=1e-14)  # h_ref 10 m
    (tmp_path / "wind.csv").write_text("altitude_agl_m,speed_mps,from_deg\n0,2,270\n1000,12,270\n")
    raw = with_wind({"model": "profile", "file": "wind.csv", "speed_scale": 1.5})
    profile = campaign_from_dict(raw, tmp_path)
    assert float(nominal_params(profile).environment.wind.velocity_n(500.0).y) == pytest.approx(1.5 * 7.0, rel=1e-14)
    with pytest.raises(ConfigError, match="^environment.wind.file: file not found"):
        campaign_from_dict(raw, CAMPAIGNS)
    with pytest.raises(ConfigError, match="^environment.wind: the 'constant' wind model needs 'from_deg'"):
        campaign_from_dict(with_wind({"model": "constant", "speed_mps": 6.0}))


def test_turbulence_section():
    """No section: no turbulence (None, no cost). W20 follows the severity unless given."""
    assert nominal_params(campaign_from_dict(with_wind({}))).environment.turbulence is None
    turbulence = nominal_params(campaign_from_dict(with_wind({}, turbulence={"severity": 2.0}))).environment.turbulence
    assert float(turbulence.w20_mps) == pytest.approx(30 * 1852 / 3600, rel=1e-14)  # moderate: 30 kt
    given = with_wind({}, turbulence={"severity": 2.0, "w20_mps": 4.0})
    assert float(nominal_params(campaign_from_dict(given)).environment.turbulence.w20_mps) == 4.0


CUSTOM = tomllib.loads((CAMPAIGNS / "custom_rocket.toml").read_text())
"""A rocket written out (no preset), its motor given by thrust_curve, propellant, grain and casing."""
LIBRARY_DEFAULTS = ("thrust_curve", "propellant_mass_kg", "grain_outer_diameter_m", "grain_inner_diameter_m",
                    "grain_length_m", "dry_mass_kg", "dry_inertia_kgm2")  # fmt: skip


def with_motor(**motor) -> dict:
    """``custom_rocket`` with its motor's curve, propellant, grain and casing replaced by ``motor``."""
    data = copy.deepcopy(CUSTOM)
    kept = {k: v for k, v in data["rocket"]["motor"].items() if k not in LIBRARY_DEFAULTS}
    data["rocket"]["motor"] = {**kept, **motor}
    return data


def test_a_designation_is_its_library_file_with_the_defaults_written_out():
    """``designation = "L1350"`` flies what the library's file flies with the header's propellant, the estimated
    grain and the casing (total − propellant, a thin tube's inertia) written out: the same nominal numbers and the
    same thrust arrays, bit for bit, and the same file digest, under the field that names it."""
    named = campaign_from_dict(with_motor(designation="L1350"), CAMPAIGNS)
    entry = find_motor("L1350")
    outer, core, length = estimated_grain(entry)
    dry = entry.total_mass_kg - entry.propellant_mass_kg
    written = campaign_from_dict(with_motor(
        thrust_curve="library/Cesaroni_4263L1350-P.eng", propellant_mass_kg=entry.propellant_mass_kg,
        grain_outer_diameter_m=outer, grain_inner_diameter_m=core, grain_length_m=length, dry_mass_kg=dry,
        dry_inertia_kgm2=list(casing_inertia_kgm2(entry, dry))), CAMPAIGNS)  # fmt: skip
    assert named.thrust_time_s.tobytes() == written.thrust_time_s.tobytes()
    assert named.thrust_n.tobytes() == written.thrust_n.tobytes()
    assert named.nominal == written.nominal
    assert named.files == {"rocket.motor.designation": written.files["rocket.motor.thrust_curve"]}
    assert named.motor == written.motor == entry
    assert named.nominal["rocket.motor.dry_mass_kg"] == dry and named.nominal["rocket.dry_mass_kg"] == 14.426
    # loaded again from its own configuration (what with_overrides and the dispersion checks validate): the same
    again = with_overrides(named, n_realizations=3)
    assert again.nominal == named.nominal and again.config.rocket.motor == named.config.rocket.motor


def test_values_given_beside_a_designation_win():
    """The file's own propellant mass, grain and casing are kept; the casing's inertia follows the dry mass given
    (0: the rocket's dry mass includes the casing, so no second casing)."""
    campaign = campaign_from_dict(with_motor(designation="L1350", propellant_mass_kg=1.95, grain_length_m=0.4,
                                             dry_mass_kg=0.0), CAMPAIGNS)  # fmt: skip
    motor = campaign.config.rocket.motor
    assert (motor.propellant_mass_kg, motor.grain_length_m, motor.dry_mass_kg) == (1.95, 0.4, 0.0)
    assert motor.dry_inertia_kgm2 == [0.0, 0.0]
    assert motor.grain_outer_diameter_m == estimated_grain(find_motor("L1350"))[0]


def test_an_existing_campaign_has_no_designation_in_its_set_up():
    """A campaign naming its curve by file keeps its set-up's JSON (and so its fingerprint and resumable runs): no
    ``designation`` key, the file digested under ``rocket.motor.thrust_curve``."""
    campaign = load_campaign(CAMPAIGNS / "custom_rocket.toml")
    motor = setup(campaign)["config"]["rocket"]["motor"]
    assert "designation" not in motor and motor["thrust_curve"] == "Cesaroni_4263L1350-P.eng"
    assert list(campaign.files) == ["rocket.motor.thrust_curve"]


@pytest.mark.parametrize(
    ("motor", "message"),
    [
        ({"designation": "L1350", "thrust_curve": "Cesaroni_4263L1350-P.eng"},
         "rocket.motor: thrust_curve and designation both name the motor; keep one"),
        ({"propellant_mass_kg": 1.9, "grain_outer_diameter_m": 0.075, "grain_inner_diameter_m": 0.02,
          "grain_length_m": 0.5}, "rocket.motor: name the motor by thrust_curve (a file) or by designation"),
        ({"designation": "K400"}, "rocket.motor.designation: 'K400' is ambiguous: AeroTech_K400C, Cesaroni_1597K400-14A"),
        ({"designation": "L13500"}, "rocket.motor.designation: 'L13500' is not a motor of the library (close: "),
        ({"designation": "L1350", "propellant_mass_kg": 9.0},
         "rocket.motor.propellant_mass_kg: 9 kg burnt over the curve's 4280 N·s is a specific impulse of 48 s"),
        ({"designation": "L1350", "propellant_mass_kg": 1.0},
         "rocket.motor.propellant_mass_kg: 1 kg burnt over the curve's 4280 N·s is a specific impulse of 436 s"),
    ],
    ids=["both", "neither", "ambiguous", "unknown", "isp-low", "isp-high"],
)  # fmt: skip
def test_a_motor_badly_named_is_one_line_naming_the_field(motor, message):
    with pytest.raises(ConfigError) as info:
        campaign_from_dict(with_motor(**motor), CAMPAIGNS)
    assert str(info.value).startswith(message) and "\n" not in str(info.value), str(info.value)


def test_a_preset_with_a_designation_is_refused():
    """A preset's dry mass includes its own motor's casing: another motor over it would count a second casing."""
    with pytest.raises(ConfigError, match=r"^rocket.motor.designation: the preset 'lynx' has its motor by thrust_curve"):
        parse_campaign(edited('preset = "lynx"', 'preset = "lynx"\nmotor.designation = "M1670"'), CAMPAIGNS)


def test_a_propellant_mass_far_from_the_header_is_warned_of():
    """10 % from the .eng header's 2.0245 kg warns (naming the field); the Lynx campaigns' 1.905 kg (5.9 % under,
    the thesis's Isp-derived mass) does not, nor a CSV curve (no header)."""
    far = campaign_from_dict(with_motor(designation="L1350", propellant_mass_kg=1.8), CAMPAIGNS)
    (line,) = motor_warnings(far)
    assert "rocket.motor.propellant_mass_kg 1.8 kg differs from the 2.0245 kg" in line and "-11%" in line
    assert motor_warnings(load_campaign(CAMPAIGNS / "custom_rocket.toml")) == []
    euroc = load_campaign(CAMPAIGNS / "lynx_euroc_sounding.toml")
    assert euroc.motor is None and motor_warnings(euroc) == []

"""Campaign validation: each kind of bad input is one line naming the field."""

from pathlib import Path

import pytest

from rocketmc.campaign.config import ConfigError, load_campaign, parse_campaign

CAMPAIGNS = Path(__file__).parents[2] / "campaigns"
NOMINAL = (CAMPAIGNS / "lynx_nominal.toml").read_text()


def edited(old: str, new: str) -> str:
    assert old in NOMINAL, old
    return NOMINAL.replace(old, new, 1)


@pytest.mark.parametrize("path", sorted(CAMPAIGNS.glob("*.toml")), ids=lambda p: p.name)
def test_shipped_campaigns_load(path):
    campaign = load_campaign(path)
    assert campaign.config.n_realizations >= 1
    assert set(campaign.config.dispersions) <= set(campaign.nominal)


def test_preset_and_override():
    campaign = parse_campaign(edited('preset = "lynx"', 'preset = "lynx"\ndry_mass_kg = 20.0'))
    assert campaign.nominal["rocket.dry_mass_kg"] == 20.0
    assert campaign.nominal["rocket.aero.linear.cn_alpha"] == pytest.approx(24.0744)  # untouched preset value


@pytest.mark.parametrize(
    ("text", "field", "words"),
    [
        (edited("n_realizations = 1000\n", ""), "n_realizations", "missing"),
        (edited("seed = 2021", 'seed = "2021"'), "seed", "integer"),
        (edited("rail_length_m = 4.0", "rail_length_m = 4.0\nrail_lenght_m = 5.0"), "launch.rail_lenght_m", "unknown key"),
        (edited('preset = "lynx"', 'preset = "lynx"\ndry_mass_kg = -1.0'), "rocket.dry_mass_kg", "greater than 0"),
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
    ],
    ids=["missing", "wrong-type", "unknown-key", "negative-mass", "elevation>90", "negative-wind", "preset",
         "thrust-file", "isp", "dispersion-path", "dispersion-range", "dispersion-params", "dispersion-kind", "toml"],
)  # fmt: skip
def test_bad_input_names_the_field(text, field, words):
    with pytest.raises(ConfigError) as info:
        parse_campaign(text, CAMPAIGNS)
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith(field), message
    assert words in message, message

"""The warnings before and after flying: a statically unstable nominal rocket, a body that looks like a unit slip,
flights beyond the aerodynamic tables' range or the build-up's subsonic theory, a parachute set above the apogee;
a rail elevation in radians refused."""

from __future__ import annotations

import tomllib

import pytest

from rocketmc.aero.buildup import MAX_SUBSONIC_MACH
from rocketmc.campaign import ConfigError, campaign_from_dict, load_campaign, read_campaign_tables
from rocketmc.campaign.checks import (
    aero_validity_warnings,
    nominal_static_margins,
    plausibility_warnings,
    preflight_warnings,
    recovery_warnings,
    stability_warnings,
)

from ..conftest import CAMPAIGNS

RAW = tomllib.loads((CAMPAIGNS / "lynx_ballistic.toml").read_text())
RAW_GEOMETRY = tomllib.loads((CAMPAIGNS.parent / "src" / "rocketmc" / "data" / "rockets" / "lynx.toml").read_text())["geometry"]


def ballistic(**rocket):
    raw = {**RAW, "rocket": {**RAW["rocket"], **rocket}, "dispersions": {}}
    return campaign_from_dict(raw, CAMPAIGNS)


@pytest.fixture(scope="module")
def lynx():
    return ballistic()


def test_lynx_is_stable_and_says_nothing(lynx):
    """Lynx: 0.27 calibers at liftoff, 0.82 at burnout (`rocketmc aero derivatives lynx`, Mach 0.3)."""
    margins = nominal_static_margins(lynx)
    assert margins["liftoff"] == pytest.approx(0.27, abs=0.01) and margins["burnout"] == pytest.approx(0.82, abs=0.01)
    assert stability_warnings(lynx) == []


def test_a_dry_cg_moved_aft_is_unstable_and_warned():
    """The dry CG 0.5 m aft moves the whole CG ~0.3 m aft (the dry mass is ~60 % of the liftoff mass): about
    −2 calibers at liftoff; the margin moves by the CG's shift over d, so one line per instant."""
    lines = stability_warnings(ballistic(preset="lynx", dry_cg_m=1.83))
    assert len(lines) == 2 and all("statically unstable" in line and "calibers" in line for line in lines), lines
    assert "at liftoff" in lines[0] and "at burnout" in lines[1]


def test_a_body_shorter_than_two_diameters_is_warned(lynx):
    """The Lynx's geometry (2.495 m, 0.150 m: 17 diameters) says nothing; its diameter given as 1.5 m (a slip of a
    decimal) makes a body 1.7 diameters long: one line naming the field, among the pre-flight warnings."""
    assert plausibility_warnings(lynx) == [] and preflight_warnings(lynx) == []
    squat = ballistic(preset="lynx", geometry={**RAW_GEOMETRY, "body_diameter_m": 1.5})
    (line,) = plausibility_warnings(squat)
    assert "rocket.geometry.body_diameter_m (1.5 m) is more than half of length_m (2.495 m)" in line, line
    assert line in preflight_warnings(squat)


def test_a_parachute_above_the_apogee_is_warned():
    """lynx_nominal's main opens 350 m above the pad after apogee: flights to 300, 340 and 350 m open it at apogee
    (at or below: the trigger is altitude ≤ 350 m once past apogee), one line; all above 350 m, none."""
    campaign = load_campaign(CAMPAIGNS / "lynx_nominal.toml")
    assert recovery_warnings(campaign, [1200.0, 351.0, float("nan")]) == []
    (line,) = recovery_warnings(campaign, [300.0, 340.0, 350.0, 1200.0, float("nan")])
    assert "rocket.parachutes.1.deploy_altitude_m (main, 350 m) is at or above the apogee of 3 of 4 flight(s)" in line


def test_a_rail_elevation_in_radians_is_refused():
    with pytest.raises(ConfigError, match=r"^launch\.elevation_deg: 1\.466 looks like radians \(84\.0°\)"):
        campaign_from_dict({**RAW, "launch": {**RAW["launch"], "elevation_deg": 1.466}}, CAMPAIGNS)


def test_flights_beyond_the_tables_are_warned(lynx):
    assert aero_validity_warnings(lynx, 0.5, 3000.0 + lynx.config.site.altitude_m) == []
    top = float(lynx.aero.body.axes[lynx.aero.body.axis_names.index("mach")][-1])
    lines = aero_validity_warnings(lynx, top + 0.1, None, outside_tables=7)
    assert any("beyond the aerodynamic tables'" in line and "mach" in line for line in lines), lines
    assert any(f"Mach {MAX_SUBSONIC_MACH:g}" in line for line in lines), lines  # built-up tables: subsonic theory
    assert any(line.startswith(f"{lynx.config.name}: 7 flight(s) left") for line in lines), lines


def test_the_subsonic_limit_holds_for_built_up_tables_only(lynx):
    """Between the build-up's Mach 0.9 and the tables' top only the theory's warning is said."""
    lines = aero_validity_warnings(lynx, MAX_SUBSONIC_MACH + 0.01)
    assert len(lines) == 1 and "subsonic theory" in lines[0], lines


def test_the_flights_maxima_and_outside_count_from_their_outputs(lynx):
    """`run`'s check after flying (and `fly`'s): the flights' largest Mach number and apogee, and the flights
    outside the tables at more than 10 % of their own maximum dynamic pressure (here 2 of 3: 5 kPa of 40, 0.1 of
    40 is not one)."""
    import numpy as np

    from rocketmc.campaign.checks import outputs_validity_warnings

    lines = outputs_validity_warnings(lynx, {"max_mach": [0.5, 0.95, np.nan], "apogee_agl_m": [3000.0, 3100.0, np.nan],
                                             "max_dynamic_pressure_pa": [4e4, 4e4, 4e4],
                                             "max_dynamic_pressure_outside_aero_tables_pa": [5e3, 1e2, 2e4]})  # fmt: skip
    assert any("Mach 0.95" in line for line in lines) and any(": 2 flight(s) left" in line for line in lines), lines


@pytest.mark.parametrize("avionics, navigation, warned", [
    ({"part": "bmx160_uncalibrated"}, "filters", ["magnetometer", "gyroscope"]),
    ({"part": "bmx160_uncalibrated", "magnetometer": {"part": "lis3mdl"}}, "filters", ["gyroscope"]),
    ({"part": "bmx160", "magnetometer": {"part": "bmx160", "hard_iron_std": 40.0}}, "filters", ["magnetometer"]),
    ({"part": "bmx160"}, "filters", []),
    ({"part": "lis3mdl_uncalibrated"}, "filters", ["magnetometer"]),
    ({"part": "thesis"}, "filters", []),
    ({"part": "bmx160_uncalibrated"}, "sensors", []),  # no filters to diverge
    ({"part": "bmx160_uncalibrated", "truth_only": True}, "filters", []),
])  # fmt: skip
def test_filters_on_uncalibrated_parts_are_warned(avionics, navigation, warned):
    """The navigation filters on an uncalibrated magnetometer (the BMX160's 40 µT, the LIS3MDL's 100 µT, or a
    calibrated part's 2 µT with 40 µT of hard iron beside it) or gyroscope (3 deg/s): one line per sensor; the
    calibrated parts (2 µT, 0.2 deg/s), the thesis's and raw-sensor navigation: none."""
    from rocketmc.campaign.checks import calibration_warnings

    raw = read_campaign_tables(CAMPAIGNS / "lynx_ballistic_gnc_1s.toml")
    raw = {**raw, "gnc": {**raw["gnc"], "navigation": navigation}, "avionics": avionics, "dispersions": {}}
    lines = calibration_warnings(campaign_from_dict(raw, CAMPAIGNS))
    assert [line.split("uncalibrated ")[1].split(" ")[0] for line in lines] == warned, lines
    assert all("navigation_diverged" in line for line in lines)

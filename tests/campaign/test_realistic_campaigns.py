"""The realistic campaigns (campaigns/*_realistic.toml): each is its thesis-faithful twin flown on hardware as a
team has it. What is checked without flying (docs/navigation.md, "The realistic campaigns"): the twin's flights
(seed, N, site, wind and turbulence draws, the closed loop, the parachutes) so that `compare` pairs them; the
calibrated parts with their per-flight spreads and no warning of an uncalibrated one; a truth field the filter
does not carry (the full IGRF-14 with an anomaly drawn per flight); a dispersed rail the navigation does not know;
the navigation initialised on the pad from what the avionics know."""

from __future__ import annotations

import pytest

from rocketmc.campaign import load_campaign
from rocketmc.campaign.checks import calibration_warnings
from rocketmc.campaign.model import nominal_params

from ..conftest import CAMPAIGNS

pytestmark = pytest.mark.slow  # campaigns or long flights: left out by make test-fast

TWINS = ["lynx_ballistic_gnc_1s", "lynx_ballistic_gnc_3p5s", "lynx_nominal_gnc_1s"]
REALISTIC_ONLY = ("avionics.", "environment.magnetic_field.", "launch.elevation_deg", "launch.azimuth_deg")
"""The dispersions a realistic campaign adds to its twin's: per-flight sensor errors, the anomaly, the rail."""


@pytest.mark.parametrize("twin", TWINS)
def test_a_realistic_campaign_flies_its_twins_flights_on_real_hardware(twin):
    thesis, realistic = (load_campaign(CAMPAIGNS / f"{name}.toml").config for name in (twin, f"{twin}_realistic"))
    assert realistic.name == f"{twin}_realistic"
    assert (realistic.seed, realistic.n_realizations) == (thesis.seed, thesis.n_realizations)
    for section in ("site", "simulation"):
        assert getattr(realistic, section) == getattr(thesis, section), section
    assert realistic.environment.wind == thesis.environment.wind
    assert realistic.environment.turbulence == thesis.environment.turbulence
    assert realistic.rocket.parachutes == thesis.rocket.parachutes
    assert (realistic.gnc.guidance, realistic.gnc.control, realistic.gnc.servo) == (
        thesis.gnc.guidance, thesis.gnc.control, thesis.gnc.servo)  # fmt: skip
    assert {p: d for p, d in realistic.dispersions.items() if not p.startswith(REALISTIC_ONLY)} == thesis.dispersions

    # The parts a team flies, calibrated: their turn-on errors drawn per flight, no uncalibrated part.
    avionics = realistic.avionics
    assert (avionics.accelerometer.part, avionics.gyroscope.part, avionics.magnetometer.part) == ("bmx160",) * 3
    assert (avionics.barometer.part, avionics.gnss.part) == ("ms5803_01ba", "neo_m9n")
    campaign = load_campaign(CAMPAIGNS / f"{twin}_realistic.toml")
    assert calibration_warnings(campaign) == []
    drawn = campaign.config.dispersions  # with the sensors' spreads (``sensor_spreads``)
    for sensor in ("accelerometer", "gyroscope", "magnetometer"):
        assert {f"avionics.{sensor}.bias.{i}" for i in range(3)} <= drawn.keys(), sensor
        assert {f"avionics.{sensor}.misalignment_deg.{i}" for i in range(3)} <= drawn.keys(), sensor
    assert "avionics.magnetometer.soft_iron.4" in drawn and "avionics.canard_feedback.bias.3" in drawn
    assert not any(getattr(avionics, s).truth_only for s in ("accelerometer", "gyroscope", "magnetometer", "gnss"))

    # The truth's field is not the filter's: the full IGRF-14 plus an anomaly drawn per flight.
    assert realistic.environment.magnetic_field.model == "igrf" and realistic.gnc.filters.attitude.field_model == "igrf"
    assert {f"environment.magnetic_field.anomaly_nt.{i}" for i in range(3)} <= drawn.keys()

    # The rail set by hand, which the navigation does not know: it starts from the nominal rail, levelled on the pad.
    assert {"launch.elevation_deg", "launch.azimuth_deg"} <= drawn.keys()
    filters = realistic.gnc.filters
    assert realistic.gnc.navigation == "filters" and filters.initialisation == "level"
    assert realistic.rocket.motor.ignition_delay_s >= filters.pad_samples * realistic.simulation.control_dt_s
    if twin == TWINS[0]:  # the set-up (gains, IGRF) takes ~10 s: once is enough to see the filters built from it
        built = nominal_params(campaign).gnc.filters
        assert built.pad_samples == filters.pad_samples and not built.heading_from_field

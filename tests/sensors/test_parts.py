"""The calibrated parts (plain names) against their ``_uncalibrated`` twins (data/sensors/SOURCE.md, "Calibrated
parts"): the same datasheet values but for the per-flight spreads a calibration leaves, which lie below the
thresholds ``run`` warns at, where the twins' lie above."""

from __future__ import annotations

import math

import pytest

from rocketmc.campaign.checks import UNCALIBRATED_FIELD_OFFSET_UT, UNCALIBRATED_GYRO_BIAS_DEG_S
from rocketmc.sensors.parts import load_part, part_names

CALIBRATION = {"bias_std", "scale_factor_std", "misalignment_std_deg", "hard_iron_std"}
"""The fields a calibrated part may change: per-flight spreads only."""


def twins() -> list[str]:
    return [name for name in part_names() if f"{name}_uncalibrated" in part_names()]


def test_every_calibrated_datasheet_part_has_its_twin():
    assert twins() == ["bmx160", "lis3mdl", "ms5803_01ba"]
    assert {n for n in part_names() if not n.endswith("_uncalibrated")} - set(twins()) == {"neo_m7n", "neo_m9n", "thesis"}


@pytest.mark.parametrize("name", twins())
def test_a_calibrated_part_changes_only_spreads_and_narrows_them(name):
    calibrated, raw = load_part(name), load_part(f"{name}_uncalibrated")
    sensors = [key for key, value in raw.items() if isinstance(value, dict)]
    assert sensors == [key for key, value in calibrated.items() if isinstance(value, dict)]
    for sensor in sensors:
        ours, theirs = calibrated[sensor], raw[sensor]
        changed = {k for k in ours.keys() | theirs.keys() if ours.get(k) != theirs.get(k)}
        assert changed <= CALIBRATION, (sensor, changed)
        assert all(c < r for c, r in zip(calibrated[sensor]["bias_std"], raw[sensor]["bias_std"])), sensor


@pytest.mark.parametrize("name", ["bmx160", "lis3mdl"])
def test_calibrated_parts_are_below_the_warning_and_raw_ones_above(name):
    for part, below in ((name, True), (f"{name}_uncalibrated", False)):
        tables = load_part(part)
        field = math.hypot(max(tables["magnetometer"]["bias_std"]), tables["magnetometer"].get("hard_iron_std", 0.0))
        assert (field < UNCALIBRATED_FIELD_OFFSET_UT) == below, part
        if "gyroscope" in tables:
            assert (max(tables["gyroscope"]["bias_std"]) < UNCALIBRATED_GYRO_BIAS_DEG_S) == below, part

"""A campaign with every error source and every fault on: the campaign tests that compare bits (resume, Dask) fly it
so that no draw, stream or set-up of the error sources can differ between chunks, processes or workers unseen.

``every_error_source`` edits a shipped full-GNC campaign's tables (lynx_nominal_gnc_1s, lynx_ballistic_gnc_1s): the
truth in the IGRF-14 with a dispersed anomaly while the MEKF carries the dipole, the calibrated datasheet parts
(BMX160, MS5803-01BA, NEO-M9N) with their per-flight spreads, hard- and soft-iron spreads, canard position sensors
with errors, the filters initialised on the pad, the guidance reference derived at set-up, air brakes flown on the
navigation by the reference-trajectory PI to a target below the nominal apogee, and every fault at probability 0.5."""

from __future__ import annotations

import copy
import tomllib
from pathlib import Path

import numpy as np
import tomli_w

from rocketmc.campaign import campaign_from_dict, read_campaign_tables

FAULT_KINDS = ("stuck_canard", "slow_canard", "gnss_outage", "magnetometer_step", "gyroscope_bias_jump",
               "accelerometer_bias_jump")  # fmt: skip
FAULTS = """
[faults.stuck_canard]
probability = 0.5
time_s = [2.0, 6.0]

[faults.slow_canard]
probability = 0.5
time_s = [1.0, 3.0]
factor = 4.0

[faults.gnss_outage]
probability = 0.5
start_s = [10.0, 14.0]
duration_s = [2.0, 5.0]

[faults.magnetometer_step]
probability = 0.5
time_s = [0.2, 3.0]
magnitude_ut = 20.0

[faults.gyroscope_bias_jump]
probability = 0.5
time_s = [1.0, 8.0]
magnitude_deg_s = 1.0

[faults.accelerometer_bias_jump]
probability = 0.5
time_s = [1.0, 8.0]
magnitude_mps2 = 0.5
"""
"""Every fault of a rocket with canards and sensors; the magnetometer's step may come on the pad, during the filters'
pad samples (0 to 0.4 s)."""
AIRBRAKE_FAULT = {"stuck_airbrakes": {"probability": 0.5, "time_s": [5.0, 12.0]}}
"""The air brakes' fault, frozen where they are, for a campaign with them (``every_error_source``)."""
EVERY_FAULT_KIND = (*FAULT_KINDS, "stuck_airbrakes")

CALIBRATED_PARTS = {
    "part": "bmx160", "accelerometer": {"cross_axis_std": 0.002},
    "magnetometer": {"hard_iron_std": 3.0, "soft_iron_std": 0.02}, "barometer": {"part": "ms5803_01ba"},
    "gnss": {"part": "neo_m9n"},
    "canard_feedback": {"lsb": 0.1, "noise_std": 0.05, "bias_std": [0.2, 0.2, 0.2, 0.2], "scale_factor_std": 0.01},
}  # fmt: skip
"""The calibrated datasheet parts with hard- and soft-iron spreads and canard position sensors with errors."""
AIRBRAKES = {"target_apogee_m": 1500.0, "controller": "reference_pi", "max_mach": 0.85,
             "panels": {"count": 3, "width_m": 0.082, "max_extension_m": 0.030}}  # fmt: skip
"""Air brakes (lynx_euroc_airbrakes.toml's panels) on the navigation, Skyward's law, 100 m below the nominal apogee."""


def every_error_source(tables: dict) -> dict:
    """``tables`` (a shipped full-GNC campaign's, the campaigns it extends merged: ``read_campaign_tables``) with every
    error source and every fault on; each edit checks that it replaces what the base has."""
    tables = copy.deepcopy(tables)
    # The truth in the IGRF-14 on the thesis's flight day with a crustal anomaly, dispersed per axis below; the MEKF
    # keeps the dipole (the base's gnc.filters.attitude.field_model).
    assert tables["environment"]["magnetic_field"] == {"model": "dipole"}
    tables["environment"]["magnetic_field"] = {"model": "igrf", "date": "2021-09-13", "anomaly_nt": [300.0, -200.0, 100.0]}
    tables["dispersions"].update({f"environment.magnetic_field.anomaly_nt.{i}": {"dist": "normal", "std": 100.0}
                                  for i in range(3)})  # fmt: skip
    # The guidance reference derived from the campaign at set-up (in every process that loads it).
    for key in ("apogee_m", "flight_path_angle_deg", "roll_heading_deg"):
        del tables["gnc"]["guidance"][key]
    # TRIAD and the gyro's mean on the pad: 20 ticks (0.4 s) before Lynx's ignition at 0.5 s.
    assert tables["gnc"]["filters"] == {"attitude": {"field_model": "dipole"}}
    tables["gnc"]["filters"].update({"initialisation": "pad", "pad_samples": 20})
    assert tables["avionics"] == {"part": "thesis"}
    tables["avionics"] = copy.deepcopy(CALIBRATED_PARTS)
    assert "airbrakes" not in tables
    tables["airbrakes"] = copy.deepcopy(AIRBRAKES)
    tables["faults"] = tomllib.loads(FAULTS)["faults"] | copy.deepcopy(AIRBRAKE_FAULT)
    return tables


def write_every_error_source(base: Path, folder: Path) -> Path:
    """``base`` with every error source (``every_error_source``) written whole as ``folder/<base's name>``, checked to
    load with each source on."""
    tables = every_error_source(read_campaign_tables(base))
    config = campaign_from_dict(tables, base.parent).config
    assert config.environment.magnetic_field.model == "igrf" and config.gnc.filters.attitude.field_model == "dipole"
    assert config.gnc.filters.initialisation == "pad" and config.gnc.guidance.apogee_m is None
    assert (config.avionics.part, config.avionics.barometer.part, config.avionics.gnss.part) == (
        "bmx160", "ms5803_01ba", "neo_m9n")  # fmt: skip
    assert set(config.faults.active()) == set(EVERY_FAULT_KIND) and config.airbrakes.controller == "reference_pi"
    spreads = {"environment.magnetic_field.anomaly_nt.0", "avionics.magnetometer.soft_iron.1",
               "avionics.magnetometer.hard_iron.2", "avionics.gyroscope.bias.0", "avionics.barometer.bias.0",
               "avionics.canard_feedback.bias.3", "avionics.accelerometer.cross_axis.5"}  # fmt: skip
    assert spreads <= set(config.dispersions), spreads - set(config.dispersions)
    path = folder / base.name
    path.write_text(tomli_w.dumps(tables))
    return path


def assert_every_fault_recorded(data: dict, n: int) -> None:
    """``data`` (a result file's ``"inputs/<name>"`` arrays, ``test_resume.contents``) records every fault, which
    some but not all of the ``n`` flights had, and the per-flight draws of the iron and the anomaly."""
    for kind in EVERY_FAULT_KIND:
        happened = data[f"inputs/faults.{kind}.happened"]
        assert happened.shape == (n,) and 0 < np.sum(happened == 1.0) < n, kind
    for name in ("environment.magnetic_field.anomaly_nt.0", "avionics.magnetometer.soft_iron.1",
                 "avionics.canard_feedback.bias.3"):  # fmt: skip
        assert len(np.unique(data[f"inputs/{name}"])) == n, name
    assert np.any(data["outputs/airbrake_deployment_time_s"] > 0.0)  # the brakes flew

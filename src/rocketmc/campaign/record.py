"""The campaign record: a validated campaign with what its files and its gain design brought."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np

from ..aero.model import LinearAero, TableAero
from ..dynamics.motor_library import MotorEntry
from ..env.weather import Weather
from ..gnc.design import Schedule
from ..gnc.airbrakes import AirbrakeParams
from .airbrakes import AirbrakeDesign
from .gains import DesignInputs
from .schema import CampaignConfig


@dataclasses.dataclass(frozen=True)
class Campaign:
    """A validated campaign: the config, its TOML text, the thrust curve, the nominal values of
    every dispersible number, keyed by dotted path (``"rocket.dry_mass_kg"``, ``"rocket.aero.ca0.2"``),
    the aerodynamic model with its tables (None for ``model = "linear"``, built per flight), the
    folder its relative file names are resolved from, the measured wind profile (altitude above
    ground [m], speed [m/s], from-direction [rad]) when the wind model is ``profile``, and with a
    [gnc] section the LQI gain schedule (``campaign/gains.py``): gains over speeds [m/s] × altitudes
    [m above mean sea level: the grid's altitudes_m plus site.altitude_m], and what it was designed from
    (``gains.DesignInputs``: the linearised aerodynamics, the rocket at burnout, the window estimate); the day's
    weather of [environment.atmosphere] (None without). Built by ``campaign/loader.py`` alone, every check run."""

    config: CampaignConfig
    text: str
    thrust_time_s: np.ndarray
    thrust_n: np.ndarray
    nominal: dict[str, float]
    aero: TableAero | LinearAero | None
    base_dir: Path
    wind_profile: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None
    files: dict[str, str] = dataclasses.field(default_factory=dict)
    gnc_schedule: Schedule | None = None
    gnc_inputs: DesignInputs | None = None
    weather: Weather | None = None
    overrides: dict[str, object] = dataclasses.field(default_factory=dict)
    """What ``with_overrides`` switched from the file (aero_model, controller, sensors, navigation, and values by
    dotted path; empty for the file as written), kept in the result file's ``overrides`` attribute."""
    motor: MotorEntry | None = None
    """The motor its thrust curve's ``.eng`` header describes (the library's for a designation); None for a CSV or
    ``.rse`` curve, or a header that is not RASP's."""
    airbrakes: AirbrakeParams | None = None
    """With [airbrakes], the brakes and their flight software as every flight flies them (``campaign.airbrakes``)."""
    airbrake_design: AirbrakeDesign | None = None
    """With [airbrakes], what their gain was designed from."""

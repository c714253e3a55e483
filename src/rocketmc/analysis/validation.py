"""The nominal flight of a campaign (``campaign.flights.simulated_flight``: as its sensors would see it) against a
real flight's log: the checks of ``rocketmc validate`` and their figure."""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from ..campaign import Campaign
from ..campaign.flights import simulated_flight
from .flight_log import FlightReduction


@dataclass(frozen=True)
class Check:
    """One simulated figure against the measured one. ``error`` is relative (a fraction) when
    ``relative`` else in ``unit``; ``tolerance`` bounds |error| (None: reported, not judged)."""

    name: str
    unit: str
    simulated: float
    measured: float
    error: float
    relative: bool
    tolerance: float | None = None

    @classmethod
    def compare(cls, name, unit, simulated, measured, tolerance=None, relative=True) -> Check:
        difference = simulated - measured
        return cls(name, unit, simulated, measured, difference / abs(measured) if relative else difference, relative, tolerance)

    @property
    def passed(self) -> bool | None:
        return None if self.tolerance is None else bool(abs(self.error) <= self.tolerance)

    def to_dict(self) -> dict:
        return {**asdict(self), "passed": self.passed}


BURN_WINDOW_S = (0.1, 3.1)
"""Where the axial specific force is compared [s from ignition]: the burn without the first sample
(the liftoff transient) and the tail-off."""


def relative_rms(simulated_t, simulated, measured_t, measured, window) -> tuple[float, float, float]:
    """(RMS of the simulated, RMS of the measured, RMS of their difference / RMS of the measured)
    over ``window`` [s], on the measured samples."""
    inside = (measured_t >= window[0]) & (measured_t <= window[1])
    reference = measured[inside]
    model = np.interp(measured_t[inside], simulated_t, simulated)
    rms = lambda x: float(np.sqrt(np.mean(x**2)))  # noqa: E731
    return rms(model), rms(reference), rms(model - reference) / rms(reference)


def simulated_descent_rate(flight: pd.DataFrame, window) -> float:
    """Mean descent rate [m/s] of the simulated flight over ``window`` [s]."""
    inside = flight[(flight.t_s >= window[0]) & (flight.t_s <= window[1])]
    return float(-inside.vertical_speed_mps.mean())


def validate_roccaraso(campaign: Campaign, reduction: FlightReduction) -> tuple[list[Check], pd.DataFrame]:
    """The campaign's nominal flight against the Roccaraso 2021 log: the checks (tolerances of
    docs/validation.md's table where it sets them) and the simulated flight."""
    r = reduction
    flight, times, _ = simulated_flight(campaign, r.landing_time_s + 20.0)
    measured_force = r.axial_specific_force
    sim_rms, log_rms, force_error = relative_rms(
        flight.t_s.to_numpy(), flight.axial_specific_force_mps2.to_numpy(),
        measured_force.t_s.to_numpy(), measured_force.specific_force_mps2.to_numpy(), BURN_WINDOW_S,
    )  # fmt: skip
    boost = flight[flight.t_s <= times["apogee_time_s"]]
    return [
        Check.compare("apogee", "m", times["apogee_agl_m"], r.apogee_agl_m, 0.03),
        Check.compare("apogee time", "s", times["apogee_time_s"], r.apogee_time_s, 0.7, relative=False),
        Check.compare("burnout time", "s", times["burnout_time_s"], r.burnout_time_s, relative=False),
        Check("axial specific force, burn RMS", "m/s²", sim_rms, log_rms, force_error, True, 0.10),
        Check.compare("max axial specific force", "m/s²", boost.axial_specific_force_mps2.max(), r.max_axial_specific_force_mps2),
        Check.compare("max airspeed", "m/s", boost.airspeed_mps.max(), r.max_airspeed_mps),
        Check.compare("descent rate under the drogue", "m/s", simulated_descent_rate(flight, r.drogue_window_s),
                      r.drogue_descent_rate_mps, 0.10),  # fmt: skip
        Check.compare("descent rate under the main", "m/s", simulated_descent_rate(flight, r.main_window_s),
                      r.main_descent_rate_mps, 0.10),  # fmt: skip
        Check.compare("landing point north", "m", times["impact_north_m"], r.landing_north_m, relative=False),
        Check.compare("landing point east", "m", times["impact_east_m"], r.landing_east_m, relative=False),
    ], flight


EUROC_2021_APOGEE_M = 3076.0
"""The measured apogee of Lynx at EuRoC 2021 [m above the pad] (docs/lynx.md; no time series is public)."""


def validate_euroc(campaign: Campaign) -> list[Check]:
    """The campaign's nominal apogee against the measured 3076 m (3 %)."""
    _, times, _ = simulated_flight(campaign, 60.0)
    return [Check.compare("apogee", "m", times["apogee_agl_m"], EUROC_2021_APOGEE_M, 0.03)]


def plot_against_log(flight: pd.DataFrame, reduction: FlightReduction, path) -> None:
    """Altitude, vertical speed, axial specific force and airspeed against time, simulated over
    measured, to a PNG at ``path``."""
    r = reduction
    fig = Figure(figsize=(12, 8), layout="constrained")
    panels = [  # label, measured t and values, simulated values, time span, value span (None: all)
        ("altitude above the pad [m]", r.altitude.t_s, r.altitude.altitude_agl_m, flight.altitude_agl_m,
         None, None),
        ("vertical speed [m/s]", r.altitude.t_s, r.altitude.vertical_speed_mps, flight.vertical_speed_mps,
         None, (-60.0, 220.0)),
        ("axial specific force [m/s²]", r.axial_specific_force.t_s, r.axial_specific_force.specific_force_mps2,
         flight.axial_specific_force_mps2, (0.0, 25.0), (-25.0, 100.0)),
        ("airspeed [m/s]", r.airspeed.t_s, r.airspeed.airspeed_mps, flight.airspeed_mps, (0.0, 25.0), None),
    ]  # fmt: skip
    for ax, (label, t_log, log_values, sim_values, xlim, ylim) in zip(fig.subplots(2, 2).ravel(), panels):
        ax.plot(t_log, log_values, color="0.4", linewidth=1.0, label="measured (Roccaraso 2021)")
        ax.plot(flight.t_s, sim_values, color="tab:red", linewidth=1.4, label="rocketmc, nominal")
        ax.set_xlabel("time from liftoff [s]")
        ax.set_ylabel(label)
        if xlim is not None:
            ax.set_xlim(*xlim)
        if ylim is not None:
            ax.set_ylim(*ylim)
        ax.grid(True, alpha=0.4)
        ax.legend(loc="best", fontsize="small")
    for event in (r.burnout_time_s, r.apogee_time_s, r.drogue_time_s, r.main_time_s):
        fig.axes[0].axvline(event, color="0.7", linewidth=0.8, linestyle=":")
    fig.suptitle("Lynx, Roccaraso 18 Sept 2021: simulated against measured\n(the baro is distorted in the boost "
                 "and at the drogue's ejection; the rocket landed 92 m above the pad)")  # fmt: skip
    fig.savefig(path, dpi=130)

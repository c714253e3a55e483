"""The state of one flight: ``FlightState`` with its ``Events`` record, the right-hand side's ``Diagnostics``
and the outcome codes ``Status``. Event times are ``inf`` until the event happens."""

from __future__ import annotations

import enum
from typing import NamedTuple

import jax.numpy as jnp

from ..dynamics import RigidBodyState
from ..env import TurbulenceState
from ..env.atmosphere import MAX_ALTITUDE_M
from ..gnc.airbrakes import AirbrakeState
from ..gnc.control import GncState
from ..pytree import pytree_dataclass
from ..sensors.avionics import AvionicsState

OUTSIDE_TABLES_QBAR_FRACTION = 0.1
"""A flight is flagged when it leaves the aero tables at a dynamic pressure above this fraction of its
maximum: near apogee or on the rail the angles are large but the loads are not."""


class Status(enum.IntEnum):
    """Outcome of one realization; the value is stored in ``/outputs/status``."""

    OK = 0
    NON_FINITE = 1
    MAX_TIME = 2
    OUTSIDE_AERO_TABLES = 3
    OUTSIDE_ATMOSPHERE = 4
    NAVIGATION_FAILED = 5

    @property
    def message(self) -> str:
        return {
            Status.OK: "ok",
            Status.NON_FINITE: "the state became NaN or infinite; the flight was stopped there",
            Status.MAX_TIME: "not on the ground at the maximum simulated time (raise max_time_s?)",
            Status.OUTSIDE_AERO_TABLES: (
                "flew outside the aerodynamic tables' range (values clamped at their edge) at more than "
                f"{OUTSIDE_TABLES_QBAR_FRACTION:.0%} of its maximum dynamic pressure"
            ),
            Status.OUTSIDE_ATMOSPHERE: (
                f"climbed above the standard atmosphere's top ({MAX_ALTITUDE_M / 1000:.1f} km above sea level), "
                "where the air was held at its value there"
            ),
            Status.NAVIGATION_FAILED: (
                "a navigation filter's covariance became non-finite or non-positive; its last good estimate was held"
            ),
        }[self]


@pytree_dataclass
class Events:
    """Event times [s] (``inf`` until they happen) and the values interpolated at them (SI, NED)."""

    rail_exit_time: jnp.ndarray
    rail_exit_speed: jnp.ndarray
    burnout_time: jnp.ndarray
    burnout_altitude: jnp.ndarray
    burnout_speed: jnp.ndarray
    apogee_time: jnp.ndarray
    apogee_altitude: jnp.ndarray
    apogee_north: jnp.ndarray
    apogee_east: jnp.ndarray
    chute_trigger_times: tuple
    impact_time: jnp.ndarray
    impact_north: jnp.ndarray
    impact_east: jnp.ndarray
    impact_speed: jnp.ndarray
    max_mach: jnp.ndarray
    max_qbar: jnp.ndarray
    max_qbar_outside_tables: jnp.ndarray
    non_finite: jnp.ndarray


class Canopy(NamedTuple):
    """What the open canopies do to the body at one instant: the squared rate of its swing under them,
    ω² = Σ|F_chute|·|arm|/I [1/s²], and their drag per unit mass and squared airspeed,
    Σ|F_chute|/(m·|v_air|²) [1/m] (quadratic drag settles the air-relative velocity v_air at a rate up to
    2·that·|v_air| [1/s])."""

    stiffness: jnp.ndarray
    drag_per_m: jnp.ndarray


@pytree_dataclass
class FlightState:
    """Time [s], the control-period counter, rigid-body state, the event record, the ``Canopy`` rates at the end
    of the last period (they bound the descent's periods), the turbulence filters (None without turbulence), the
    closed loop's state (None without a controller), the avionics' (None without sensors) and the air brakes' (None
    without them).

    tick: control periods flown (int32, +1 per ``control_step``, after landing too, as ``t``). A longer period of
    steady descent (``steady_descent``: the GNC idle) counts one too, as does,
    without a controller and sensors, a period ending at an event (``sim.flight.event_period``), so with them
    ``t = tick·control_dt_s`` (up to the rounding of the summed periods) only until the first long period."""

    t: jnp.ndarray
    tick: jnp.ndarray
    body: RigidBodyState
    events: Events
    canopy: Canopy
    turbulence: TurbulenceState | None
    gnc: GncState | None = None
    avionics: AvionicsState | None = None
    airbrakes: AirbrakeState | None = None


class Diagnostics(NamedTuple):
    """By-products of the right-hand side: Mach [-], dynamic pressure [Pa], the ``Canopy`` rates, and
    the dynamic pressure if the aerodynamic tables were left (not under a canopy), else 0 [Pa]."""

    mach: jnp.ndarray
    qbar: jnp.ndarray
    canopy: Canopy
    qbar_outside_tables: jnp.ndarray



def done(state: FlightState):
    """True once the flight has landed or stopped on a non-finite state."""
    return jnp.isfinite(state.events.impact_time) | state.events.non_finite

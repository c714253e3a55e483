"""One realization flown exactly as the campaign flies it, with its full time series: ``rocketmc fly``, the
trajectories a run keeps (``run --trajectories``), and the flights ``validate`` and ``sensors simulate`` record.

The flight is ``sim.flight.fly``, the step every campaign flies, on ``runner.LANES`` vmapped lanes that all hold
it, its parameters made inside the vmap from the realization's index as the runner makes them: the same vector
code, hence the same bits as the campaign's row to an ulp (one unbatched flight differs by more, seen: 1e-12 m at
impact; the vmapped lanes by 1e-15 m, seen on lynx_ballistic). Its summary is ``flight_summary`` of the state at
the end of the first block of ``block_steps`` periods at which the flight is done, where the runner stops it.

Sample k is the state at the start of period k (the first at t = 0 at rest on the rail), with ``sim.loads.loads``
there: the gust and canard deflections of the period starting at that instant, i.e. its first RK4 stage. The
periods are the flight's own (``control_dt_s``, longer in steady descent under canopy, shorter at events without a
controller: ``sim.flight.event_period``). Positions along the rocket (CG, centre of pressure) are distances from the
nose tip [m], angles in degrees, everything else SI.

Every recorded flight is compiled once per campaign structure and kind (``compiled_flight``), kept per process.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Hashable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import jax
import jax.numpy as jnp
import numpy as np

from ..aero.stability import centre_of_pressure_at
from ..dynamics.servo import deflection_at
from ..env import G0, isa
from ..errors import RocketmcError
from ..math import Vec3
from ..sim.flight import flight_done, fly, initial_state, period_gust
from ..sim.loads import derivatives, loads
from ..sim.outputs import DEPLOY_TIME_SUFFIX, Metric, flight_summary
from .record import Campaign
from .program import cached_program, program_numbers, structure_fingerprint, with_numbers
from .model import flight_params, nominal_params
from .runner import LANES, realization_params, sim_settings
from .sampling import realization_key

if TYPE_CHECKING:  # imported where a frame is made: pandas takes ~0.2 s, before a run's first flight
    import pandas as pd


def _kept(state):
    """The part of a ``FlightState`` the record keeps: all but the sensors' and the navigation filters' state."""
    gnc = None if state.gnc is None else dataclasses.replace(state.gnc, navigation=None)
    return dataclasses.replace(state, avionics=None, gnc=gnc)


def _deflections(p, state):
    """The canard deflections at the period start [rad]: the servos' with their offsets, or neutral."""
    if p.gnc is None or p.gnc.servo is None:
        return jnp.zeros(p.rocket.aero.n_canards)
    return deflection_at(p.gnc.servo, state.gnc.servo, 0.0)


def _deployment(state):
    """The air brakes' deployment at the period start (None without air brakes)."""
    return None if state.airbrakes is None else state.airbrakes.servo.deflection_rad


def _at_start(p, state):
    """What the model computes at the start of the period beginning at ``state`` (SI, body FRD / NED)."""
    _, _, gust = period_gust(p, state)
    deflections = _deflections(p, state)
    f = loads(state.t, state.body, p, deflections, gust, state.events, _deployment(state))
    cp_x = centre_of_pressure_at(p.rocket.aero, f.air, f.mass.cg_x)
    return {
        "loads": f, "deflections": deflections,
        # u/V = cos α cos β for α = atan2(w, u), β = asin(v/V): the body axis against the air-relative velocity
        "total_alpha": jnp.arccos(jnp.clip(jnp.cos(f.air.alpha) * jnp.cos(f.air.beta), -1.0, 1.0)),
        "cp_x": cp_x,
        "static_margin": (f.mass.cg_x - cp_x) / p.rocket.aero.reference_length_m,
        "aero_power": state.body.q_nb.rotate(f.aero_force_b).dot(state.body.v_n),
    }  # fmt: skip


def _power_at_end(p, start, end):
    """The aerodynamic force's power [W] at the end of the period from ``start`` to ``end``, with that period's
    gust and the events at its start (as its RK4 stages saw them)."""
    _, _, gust = period_gust(p, start)
    f = loads(end.t, end.body, p, _deflections(p, end), gust, start.events, _deployment(end))
    return end.body.q_nb.rotate(f.aero_force_b).dot(end.body.v_n)


class RealizationError(RocketmcError, ValueError):
    """A realization that is not one of the campaign's."""


_compiled: dict = {}
"""The one compiled recorded flight a process keeps: each holds ~15 000 periods' buffers."""


def compiled_flight(campaign: Campaign, kind: Hashable, build: Callable[[Campaign], Callable]) -> Callable:
    """``build(campaign)`` with the campaign's numbers as arguments (``program.with_numbers``), exported into the cache
    folder by the campaign's structure (``program.structure_fingerprint``), ``kind`` (what is recorded, how) and the
    arguments' shapes (``program.cached_program``), and kept compiled per process, one at a time: the function of
    ``build``'s arguments, the campaign's numbers bound."""
    key, numbers = (structure_fingerprint(campaign), repr(kind)), program_numbers(campaign)

    def run(*args):
        if _compiled.get("key") != key:
            _compiled.clear()
            function = jax.jit(lambda numbers, *args: build(with_numbers(campaign, numbers))(*args))
            _compiled.update(key=key, run=cached_program("flight", "".join(key), function, numbers, *args).compiled(
                numbers, *args))  # fmt: skip
        return _compiled["run"](numbers, *args)

    return run


def _flight_function(campaign: Campaign, nominal: bool):
    """The recorded flight: (index, the master key's data) -> (samples, end-of-period powers, per-period summaries,
    statuses, done flags)."""
    settings = sim_settings(campaign)
    longest = math.ceil(settings.max_time_s / settings.control_dt_s)  # periods last at least control_dt_s
    n_periods = -(-longest // settings.block_steps) * settings.block_steps

    def params_of(index, master):
        if nominal:  # ``campaign.nominal_params``, with the index traced as the runner's
            return flight_params(campaign, campaign.nominal, realization_key(master, index))
        return realization_params(campaign, master, index)[0]

    def lane(index, master):
        p = params_of(index, master)
        record = lambda s: (_kept(s), *flight_summary(p, s), flight_done(settings, s))  # noqa: E731
        return fly(p, settings, n_periods, record=record)[1]

    def flown(index, key_data):
        master = jax.random.wrap_key_data(key_data)
        states, summaries, statuses, done = jax.tree_util.tree_map(
            lambda x: x[0], jax.vmap(lane, in_axes=(0, None))(jnp.full(LANES, index, dtype=jnp.uint32), master))  # fmt: skip
        p = params_of(index, master)
        states = jax.tree_util.tree_map(lambda a, b: jnp.concatenate([a[None], b]), _kept(initial_state(p)), states)
        first = jax.tree_util.tree_map(lambda x: x[:-1], states)
        then = jax.tree_util.tree_map(lambda x: x[1:], states)
        samples = jax.vmap(lambda s: _at_start(p, s))(states)
        power_end = jax.vmap(lambda a, b: _power_at_end(p, a, b))(first, then)
        jumps = jnp.stack([jnp.asarray(a, dtype=float) for a in p.environment.wind.jump_altitudes_m()] or [jnp.zeros(0)])
        return states, samples, power_end, summaries, statuses, done, jumps.ravel()

    return flown


@dataclass(frozen=True)
class FlightRecord:
    """One flight: ``series`` (a DataFrame, one row per period start, columns named as ``units``' keys), the units
    and meanings of its columns, its ``flight_summary`` (host floats, the campaign row's bits) and status code,
    ``aero_power_end_w``: the aerodynamic force's power at the end of each period but the last, with that
    period's gust [W], and ``wind_jumps_m``, the heights above the pad where the mean wind jumps [m] (both for
    ``energy_balance``), and the campaign and realization (None: the nominal flight)."""

    campaign: Campaign
    realization: int | None
    series: pd.DataFrame
    columns: dict[str, Metric]
    summary: dict[str, float]
    status: int
    aero_power_end_w: np.ndarray
    wind_jumps_m: np.ndarray

    @property
    def label(self) -> str:
        which = "nominal flight" if self.realization is None else f"realization {self.realization}"
        return f"{self.campaign.config.name}, {which}"


def check_realization(campaign: Campaign, realization: int | None, option: str = "--realization") -> None:
    """A one-line RealizationError naming ``option`` unless ``realization`` is None (the nominal flight) or one of
    ``campaign``'s."""
    n = campaign.config.n_realizations
    if realization is not None and not 0 <= realization < n:
        raise RealizationError(f"{option} {realization}: not a realization of {campaign.config.name} (0 to {n - 1})")


def flight_record(campaign: Campaign, realization: int | None = None) -> FlightRecord:
    """The ``FlightRecord`` of ``campaign``'s nominal flight (its undispersed values and realization 0's
    turbulence noise, ``campaign.nominal_params``) or of realization ``realization``. ValueError for a realization
    outside the campaign."""
    check_realization(campaign, realization)
    nominal = realization is None
    run = compiled_flight(campaign, ("record", nominal), lambda flying: _flight_function(flying, nominal))
    master = jax.random.key_data(jax.random.key(campaign.config.seed))
    states, samples, power_end, summaries, statuses, done, jumps = jax.tree_util.tree_map(
        np.asarray, run(np.uint32(realization or 0), master))  # fmt: skip
    steps = sim_settings(campaign).block_steps
    block_ends = np.arange(steps - 1, len(done), steps)
    end = block_ends[np.argmax(done[block_ends])]  # the runner's last block
    summary = {k: float(v[end]) for k, v in summaries.items()}
    status = int(statuses[end])
    impact = summary["impact_time_s"]
    t = states.t
    last = end + 1 if math.isnan(impact) else int(np.argmax(t >= impact))  # samples through impact
    keep = slice(0, last + 1)
    series, columns = _series(campaign, jax.tree_util.tree_map(lambda x: x[keep], states),
                              jax.tree_util.tree_map(lambda x: x[keep], samples), summary)  # fmt: skip
    return FlightRecord(campaign, realization, series, columns, summary, status, power_end[:last], jumps)


def _series(campaign: Campaign, states, samples, summary) -> tuple[pd.DataFrame, dict[str, Metric]]:
    """The time-series columns (name -> array) and their ``Metric``s from the sampled states and loads (numpy)."""
    rocket = campaign.config.rocket
    nose = rocket.from_nose(rocket.reference_point_m)  # the body origin's distance from the nose tip [m]
    body, f = states.body, samples["loads"]
    air, mass = f.air, f.mass
    yaw, pitch, roll = (np.degrees(np.asarray(a)) for a in body.q_nb.to_euler())
    deg = np.degrees
    columns: dict[str, tuple[np.ndarray, str, str]] = {
        "time": (states.t, "s", "time since the start on the rail (ignition at rocket.motor.ignition_delay_s)"),
        "north": (body.r_n.x, "m", "CG north of the pad"),
        "east": (body.r_n.y, "m", "CG east of the pad"),
        "altitude": (-body.r_n.z, "m", "CG altitude above the pad"),
        "v_north": (body.v_n.x, "m/s", "CG velocity north"),
        "v_east": (body.v_n.y, "m/s", "CG velocity east"),
        "v_down": (body.v_n.z, "m/s", "CG velocity down"),
        "speed": (np.sqrt(body.v_n.x**2 + body.v_n.y**2 + body.v_n.z**2), "m/s", "CG speed over ground"),
        **{f"q_{c}": (getattr(body.q_nb, c), "1", f"attitude quaternion q_nb, {c} component (scalar first)")
           for c in "wxyz"},
        "yaw": (yaw, "deg", "3-2-1 Euler yaw, clockwise from north"),
        "pitch": (pitch, "deg", "3-2-1 Euler pitch, above the horizon"),
        "roll": (roll, "deg", "3-2-1 Euler roll"),
        "p": (deg(body.omega_b.x), "deg/s", "body roll rate (FRD x)"),
        "q": (deg(body.omega_b.y), "deg/s", "body pitch rate (FRD y)"),
        "r": (deg(body.omega_b.z), "deg/s", "body yaw rate (FRD z)"),
        "airspeed": (air.airspeed, "m/s", "speed relative to the air (mean wind and gust)"),
        "alpha": (deg(air.alpha), "deg", "angle of attack atan2(w, u) of the air-relative velocity"),
        "beta": (deg(air.beta), "deg", "sideslip asin(v/V) of the air-relative velocity"),
        "total_alpha": (deg(samples["total_alpha"]), "deg", "angle between the body axis and the air-relative velocity"),
        "mach": (air.mach, "1", "Mach number"),
        "dynamic_pressure": (air.qbar, "Pa", "dynamic pressure ½ρV²"),
        "density": (air.density, "kg/m^3", "air density (the campaign's atmosphere)"),
        "thrust": (f.thrust_n, "N", "motor thrust along the body axis"),
        **{f"aero_force_{a}": (getattr(f.aero_force_b, a), "N", f"aerodynamic force, body {a} (FRD)") for a in "xyz"},
        **{f"chute_force_{n}": (getattr(f.chute_force_n, a), "N", f"parachutes' force, {n}")
           for a, n in zip("xyz", ("north", "east", "down"))},
        **{f"moment_{a}": (getattr(f.moment_b, a), "N·m", f"moment of all forces about the CG, body {a} (FRD)")
           for a in "xyz"},
        "mass": (mass.mass, "kg", "mass, propellant included"),
        "cg": (nose - mass.cg_x, "m", "centre of mass from the nose tip"),
        "ixx": (mass.ixx, "kg·m^2", "axial moment of inertia about the CG"),
        "iyy": (mass.iyy, "kg·m^2", "transverse moment of inertia about the CG"),
        "cp": (nose - samples["cp_x"], "m", "centre of pressure from the nose tip: x_ref + d·Cmα/CNα at the flight's "
               "Mach, small angle"),
        "static_margin": (samples["static_margin"], "cal", "static margin (CP − CG)/d, d the reference length"),
        "mechanical_energy": (0.5 * mass.mass * (body.v_n.x**2 + body.v_n.y**2 + body.v_n.z**2) - mass.mass * G0 * body.r_n.z,
                              "J", "½mV² + m·g0·altitude of the CG"),
        "aero_power": (samples["aero_power"], "W", "power of the aerodynamic force on the CG's motion, F·v"),
    }  # fmt: skip
    if states.airbrakes is not None:
        brakes = states.airbrakes
        columns["airbrake_deployment"] = (brakes.servo.deflection_rad, "1", "air brakes' deployment at the period start "
                                          "(0 retracted, 1 fully out)")  # fmt: skip
        columns["airbrake_command"] = (brakes.servo.command_rad, "1", "air brakes' command held over the period before")
        columns["predicted_apogee"] = (brakes.predicted_apogee_m, "m", "the brakes' software's apogee prediction above the "
                                       "pad at the period before's start (NaN while the brakes may not open or fly "
                                       "the reference-trajectory PI)")  # fmt: skip
        if brakes.reference is not None:
            r, chosen = campaign.airbrakes.reference, np.asarray(brakes.reference.trajectory)
            every = np.array([np.interp(-np.asarray(body.r_n.z), r.heights_m, climb) for climb in r.climb_mps])
            along = np.take_along_axis(every, np.maximum(chosen, 0)[None], axis=0)[0]
            columns["reference_climb"] = (np.where(chosen >= 0, along, np.nan), "m/s", "the chosen reference's climb rate "
                                          "at the true height (NaN before the brakes' PI chose one)")  # fmt: skip
    if states.gnc is not None and campaign.config.gnc.canards:
        for i in range(samples["deflections"].shape[1]):
            columns[f"canard_{i + 1}"] = (deg(samples["deflections"][:, i]), "deg", f"canard {i + 1} deflection, offset included")
        for a, name in zip("xyz", ("yaw", "pitch", "roll")):
            columns[f"command_{name}"] = (deg(getattr(states.gnc.command, a)), "deg", f"virtual {name} command held")
        for a, name in zip("xyz", ("p", "q", "r")):
            columns[f"integrator_{name}"] = (deg(getattr(states.gnc.integrators, a)), "deg",
                                             f"LQI rate-error integrator e_{name}")  # fmt: skip
    import pandas as pd

    frame = pd.DataFrame({name: np.asarray(v[0], dtype=float) for name, v in columns.items()})
    frame["phase"] = _phases(campaign, frame["time"].to_numpy(), summary)
    units = {name: Metric(unit, meaning) for name, (_, unit, meaning) in columns.items()}
    units["phase"] = Metric("-", "rail, powered, coast, the last parachute deployed, landed")
    return frame, units


def _phases(campaign: Campaign, t, summary) -> np.ndarray:
    """The flight phase at each time ``t`` [s] from the summary's event times."""
    phase = np.full(t.shape, "rail", dtype=object)
    marks = [("powered", summary["rail_exit_time_s"]), ("coast", summary["burnout_time_s"])]
    marks += [(c.name, summary[c.name + DEPLOY_TIME_SUFFIX]) for c in campaign.config.rocket.parachutes]
    marks += [("landed", summary["impact_time_s"])]
    for name, time in sorted((m for m in marks if not math.isnan(m[1])), key=lambda m: m[1]):
        phase[t >= time] = name
    return phase


TRAJECTORY_RULE = ("the flight record's series (rocketmc fly --realization I) decimated: the first sample in each "
                   "interval_s-long bin of time [k*interval_s, (k+1)*interval_s) and the last (at or after impact)")
"""What ``/trajectories`` of a result file holds (its ``description`` attribute)."""


def decimate(series: pd.DataFrame, interval_s: float) -> pd.DataFrame:
    """The rows of ``series`` that are the first in each ``interval_s``-long bin of time [k·S, (k+1)·S) [s], and
    its last row: at most t_end/S + 2 rows, every row when the periods are longer than S."""
    bins = np.floor(series["time"].to_numpy() / interval_s)
    keep = np.diff(bins, prepend=-1.0) > 0
    keep[-1] = True
    return series[keep].reset_index(drop=True)


def trajectories(campaign: Campaign, realizations, interval_s: float):
    """For each of ``realizations`` of ``campaign``, its ``FlightRecord`` (the campaign's bits) with the series
    ``decimate``d to ``interval_s`` [s] (``samples``: its length before), as a run keeps it."""
    for index in realizations:
        record = flight_record(campaign, index)
        yield dataclasses.replace(record, series=decimate(record.series, interval_s)), len(record.series)


def simulated_flight(campaign: Campaign, duration_s: float = 150.0) -> tuple[pd.DataFrame, dict, int]:
    """The campaign's nominal flight as its sensors would see it, for comparison with a flight log, sampled every
    control period until ``duration_s`` after ignition or the impact. Times are from motor ignition [s] (a log's
    liftoff sample: the L1350 lifts the rocket within a sample of lighting); heights above the pad [m]; the specific
    force along the body x axis [m/s²] is what an accelerometer on the axis reads (on the rail too). Returns a
    DataFrame (``t_s``, ``altitude_agl_m``, ``vertical_speed_mps``, ``airspeed_mps``, ``axial_specific_force_mps2``),
    the summary (times from ignition) and the status code."""
    params = nominal_params(campaign)
    settings = sim_settings(campaign)
    ignition = float(params.rocket.motor.ignition_time_s)
    n_periods = int(np.ceil((duration_s + ignition) / settings.control_dt_s))

    def sensed(p):
        final, trajectory = fly(p, settings, n_periods)
        neutral = jnp.zeros(p.rocket.aero.n_canards)

        def at(state):
            d_body, diagnostics = derivatives(state.t, state.body, p, neutral, Vec3.zeros(state.t), state.events)
            gravity = p.environment.gravity_mps2(p.environment.site_altitude_m - state.body.r_n.z)
            gravity_free = d_body.v_n - Vec3(0.0, 0.0, gravity)
            return state.body.q_nb.rotate_inverse(gravity_free).x, diagnostics.mach

        force, mach = jax.vmap(at)(trajectory)
        return final, trajectory, force, mach

    final, trajectory, force, mach = compiled_flight(campaign, ("sensed", n_periods), lambda _: sensed)(params)
    summary, status = flight_summary(params, final)
    altitude = -np.asarray(trajectory.body.r_n.z)
    speed_of_sound = np.asarray(isa(float(params.environment.site_altitude_m) + altitude).speed_of_sound)
    import pandas as pd

    flight = pd.DataFrame({
        "t_s": np.asarray(trajectory.t) - ignition,
        "altitude_agl_m": altitude,
        "vertical_speed_mps": -np.asarray(trajectory.body.v_n.z),
        "airspeed_mps": np.asarray(mach) * speed_of_sound,
        "axial_specific_force_mps2": np.asarray(force),
    })  # fmt: skip
    times = {k: float(v) - ignition if k.endswith("time_s") else float(v) for k, v in summary.items()}
    until = min(duration_s, times["impact_time_s"]) if np.isfinite(times["impact_time_s"]) else duration_s
    return flight[flight.t_s <= until].reset_index(drop=True), times, int(status)

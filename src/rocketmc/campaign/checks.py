"""Checks of a campaign before and after flying that warn rather than refuse: a nominal rocket that is
statically unstable (someone may fly one on purpose, to see where it lands), navigation filters on an uncalibrated
magnetometer or gyroscope, a propellant mass far from its motor's ``.eng`` header, and flights beyond the range of the aerodynamic tables or of the method that built them.
Each returns the warning lines (none: all is well), for ``run``, ``fly`` and ``report`` alike."""

from __future__ import annotations

import math

import numpy as np

from ..aero.buildup import MAX_SUBSONIC_MACH
from ..aero.model import LinearAero, linear_derivatives, simplify
from ..aero.stability import centre_of_pressure_x_m, static_margin_calibers
from ..gnc.navigation import NavigationMode
from ..sim.loads import mass_properties
from ..sim.params import FlightParams
from ..sim.state import OUTSIDE_TABLES_QBAR_FRACTION
from .limits import PROPELLANT_HEADER_TOLERANCE
from .record import Campaign
from .model import nominal_params

MARGIN_MACH = 0.3
"""Mach number at which the pre-flight static margin is read (the slopes' value early in the ascent)."""


def liftoff_and_burnout_cg_x_m(params: FlightParams) -> dict[str, float]:
    """Body-frame x of the rocket's centre of mass at liftoff (t = 0, full motor) and at burnout [m, from the
    reference point, positive toward the nose]."""
    motor = params.rocket.motor
    times = {"liftoff": 0.0, "burnout": float(motor.ignition_time_s + motor.burn_time_s)}
    return {when: float(mass_properties(params, t).cg_x) for when, t in times.items()}


def nominal_static_margins(campaign: Campaign, mach: float = MARGIN_MACH) -> dict[str, float]:
    """The nominal rocket's static margin [calibers] at liftoff and at burnout (``static_margin_calibers``),
    the slopes read at ``mach`` and the pad's altitude."""
    params = nominal_params(campaign)
    altitude = campaign.config.site.altitude_m
    return {when: static_margin_calibers(params.rocket.aero, x, mach, altitude)
            for when, x in liftoff_and_burnout_cg_x_m(params).items()}  # fmt: skip


def stability_warnings(campaign: Campaign, mach: float = MARGIN_MACH) -> list[str]:
    """One line per instant (liftoff, burnout) at which the nominal rocket's static margin is negative (or
    undefined: no restoring normal force)."""
    return [
        f"{campaign.config.name}: the nominal rocket is statically unstable at {when}: static margin {margin:.2f} "
        f"calibers at Mach {mach:g} (centre of pressure ahead of the centre of mass)"
        for when, margin in nominal_static_margins(campaign, mach).items()
        if not margin >= 0
    ]


UNCALIBRATED_FIELD_OFFSET_UT = 10.0
"""A magnetometer whose per-flight offset spread (sensor bias and hard iron together, per axis) exceeds this is
uncalibrated: 5x what an ellipsoid fit leaves (2 µT, data/sensors/SOURCE.md), a quarter of the BMX160's raw 40 µT;
10 µT on each axis (17 µT) of a ~47 µT field turns its direction by up to 22°, beyond the 10° of a diverged estimate
(``gnc.navigation.DIVERGED_ATTITUDE_RAD``)."""
UNCALIBRATED_GYRO_BIAS_DEG_S = 1.0
"""A gyroscope whose per-flight bias spread exceeds this [deg/s, per axis] is uncalibrated: 5x what averaging on the
pad leaves (0.2 deg/s), a third of the BMX160's raw 3 deg/s; 1 deg/s over a 10 s window is 10° of attitude."""


def calibration_warnings(campaign: Campaign) -> list[str]:
    """One line per sensor the navigation filters read whose per-flight offset spread is an uncalibrated part's:
    the magnetometer above ``UNCALIBRATED_FIELD_OFFSET_UT``, the gyroscope above ``UNCALIBRATED_GYRO_BIAS_DEG_S``
    (none without [gnc] navigation = "filters", or for a truth-only sensor)."""
    cfg = campaign.config
    if cfg.gnc is None or NavigationMode(cfg.gnc.navigation) is not NavigationMode.FILTERS or cfg.avionics is None:
        return []
    mag, gyro = cfg.avionics.magnetometer, cfg.avionics.gyroscope
    spreads = {
        "magnetometer": (mag, math.hypot(max(mag.bias_std), mag.hard_iron_std), UNCALIBRATED_FIELD_OFFSET_UT, "µT",
                         "an ellipsoid fit in the airframe leaves ~2 µT"),
        "gyroscope": (gyro, max(gyro.bias_std), UNCALIBRATED_GYRO_BIAS_DEG_S, "deg/s",
                      "averaging it on the pad leaves ~0.2 deg/s"),
    }  # fmt: skip
    return [
        f"{cfg.name}: the navigation filters read an uncalibrated {sensor} (part {config.part!r}: its per-flight offset "
        f"spread {spread:.3g} {unit} exceeds {limit:g} {unit}; {calibrated}): expect its estimate to diverge "
        f"(/outputs/navigation_diverged); the calibrated parts are docs/sensors.md's"
        for sensor, (config, spread, limit, unit, calibrated) in spreads.items()
        if not config.truth_only and spread > limit
    ]


def motor_warnings(campaign: Campaign) -> list[str]:
    """One line if the propellant mass differs from its ``.eng`` header's (``Campaign.motor``) by more than
    ``PROPELLANT_HEADER_TOLERANCE``; none without a header."""
    header, given = campaign.motor, campaign.config.rocket.motor.propellant_mass_kg
    if header is None or abs(given / header.propellant_mass_kg - 1.0) <= PROPELLANT_HEADER_TOLERANCE:
        return []
    return [f"{campaign.config.name}: rocket.motor.propellant_mass_kg {given:g} kg differs from the "
            f"{header.propellant_mass_kg:g} kg of its motor's .eng header ({header.name}, {header.designation}) by "
            f"{given / header.propellant_mass_kg - 1.0:+.0%}: another motor's mass, or a typo?"]


SHORTEST_FINENESS = 2.0
"""A body shorter than this many diameters (nose tip to aft end over the body diameter) is warned of: a radius given as
the diameter, or a length in another unit, passes the ranges; the squattest flying rockets are still ~4 diameters."""


def plausibility_warnings(campaign: Campaign) -> list[str]:
    """Values that pass their ranges but look like a unit slip: a body shorter than ``SHORTEST_FINENESS`` diameters."""
    geometry = campaign.config.rocket.geometry
    if geometry is None or geometry.length_m >= SHORTEST_FINENESS * geometry.body_diameter_m:
        return []
    return [f"{campaign.config.name}: rocket.geometry.body_diameter_m ({geometry.body_diameter_m:g} m) is more than "
            f"half of length_m ({geometry.length_m:g} m): a body {geometry.length_m / geometry.body_diameter_m:.2g} "
            "diameters long; a radius given as the diameter, or a length in another unit?"]


def preflight_warnings(campaign: Campaign) -> list[str]:
    """Every warning about a campaign before it flies: stability, calibration, motor and plausibility."""
    return (stability_warnings(campaign) + calibration_warnings(campaign) + motor_warnings(campaign)
            + plausibility_warnings(campaign))  # fmt: skip


def recovery_warnings(campaign: Campaign, apogee_agl_m) -> list[str]:
    """One line per parachute set to open at an altitude (``deploy_altitude_m``) at or above the apogee [m above the
    pad] of some of the flights given: there it opens at apogee instead (a main set in feet, or a lower flight than
    expected)."""
    flown = np.asarray(apogee_agl_m, float)
    flown = flown[np.isfinite(flown)]
    lines = []
    for i, chute in enumerate(campaign.config.rocket.parachutes):
        below = int((flown <= chute.deploy_altitude_m).sum()) if chute.deploy_altitude_m is not None else 0
        if below:
            lines.append(f"{campaign.config.name}: rocket.parachutes.{i}.deploy_altitude_m ({chute.name}, "
                         f"{chute.deploy_altitude_m:g} m) is at or above the apogee of {below} of {flown.size} "
                         f"flight(s) (median apogee {np.median(flown):.0f} m above the pad): it opens at apogee there")  # fmt: skip
    return lines


def aero_validity_warnings(campaign: Campaign, max_mach: float, max_altitude_m: float | None = None,
                           outside_tables: int = 0) -> list[str]:  # fmt: skip
    """Warning lines where flights went beyond the aerodynamic method: ``max_mach`` (the largest Mach number
    flown) above the tables' Mach axis (values clamped at its edge) or, for built-up tables, above the
    subsonic theory's ``MAX_SUBSONIC_MACH``; ``max_altitude_m`` [m MSL] above the tables' altitude axis;
    ``outside_tables`` flights that flew outside any axis (α, β, Mach, altitude) at more than
    ``sim.state.OUTSIDE_TABLES_QBAR_FRACTION`` of their maximum dynamic pressure (status 3's criterion, counted
    whatever status a flight ended with). NaN maxima (no flight ok) are skipped."""
    aero = campaign.aero if campaign.aero is not None else nominal_params(campaign).rocket.aero
    tables = [aero.table] if isinstance(aero, LinearAero) else [t for t in (aero.body, aero.canard_table) if t]
    name, lines = campaign.config.name, []
    for axis, flown, unit in (("mach", max_mach, ""), ("altitude", max_altitude_m, " m")):
        tops = [float(np.max(t.axes[t.axis_names.index(axis)])) for t in tables if axis in t.axis_names]
        if flown is not None and tops and flown > min(tops):
            lines.append(f"{name}: flights reach {axis} {flown:.4g}{unit}, beyond the aerodynamic tables' "
                         f"{min(tops):.4g}{unit} (coefficients held at the edge)")  # fmt: skip
    rocket = campaign.config.rocket
    if rocket.aero.model != "linear" and rocket.aero.tables == "buildup" and not math.isnan(max_mach) \
            and max_mach > MAX_SUBSONIC_MACH:  # fmt: skip
        lines.append(f"{name}: flights reach Mach {max_mach:.3g}, beyond the build-up's subsonic theory "
                     f"(Mach {MAX_SUBSONIC_MACH:g}; compressibility held there)")  # fmt: skip
    if outside_tables:
        lines.append(f"{name}: {outside_tables} flight(s) left the aerodynamic tables' range (angle of attack, "
                     f"sideslip, Mach or altitude) at more than {OUTSIDE_TABLES_QBAR_FRACTION:.0%} of their maximum "
                     "dynamic pressure")  # fmt: skip
    return lines


VALIDITY_OUTPUTS = ("max_mach", "apogee_agl_m", "max_dynamic_pressure_pa", "max_dynamic_pressure_outside_aero_tables_pa")
"""The per-flight outputs ``outputs_validity_warnings`` reads."""


def outputs_validity_warnings(campaign: Campaign, outputs) -> list[str]:
    """``aero_validity_warnings`` and ``recovery_warnings`` of flights given by their ``outputs``
    (``VALIDITY_OUTPUTS``' names to one value per flight: a result file's /outputs or one flight's summary): the
    largest Mach number and altitude flown, how many flights were outside the tables by status 3's criterion, and
    the parachutes set above some flights' apogee."""
    top = lambda values: float(np.nanmax(values)) if np.isfinite(values).any() else float("nan")  # noqa: E731
    values = {name: np.asarray(outputs[name], float) for name in VALIDITY_OUTPUTS}
    qbar = values["max_dynamic_pressure_pa"]
    outside = int((values["max_dynamic_pressure_outside_aero_tables_pa"] > OUTSIDE_TABLES_QBAR_FRACTION * qbar).sum())
    return aero_validity_warnings(campaign, top(values["max_mach"]), top(values["apogee_agl_m"])
                                  + campaign.config.site.altitude_m, outside) + recovery_warnings(
        campaign, values["apogee_agl_m"])  # fmt: skip


def aero_derivatives(campaign: Campaign, mach: float, altitude_m: float) -> dict:
    """The linear aerodynamic derivatives of ``campaign``'s rocket (its model, simplified if it is a table) at
    ``mach`` and ``altitude_m`` [m], with its centre of pressure, CG and static margin at liftoff and at burnout
    (``rocketmc aero derivatives``). Positions are distances from the nose tip [m]; coefficients per rad, rates per
    ω·d/(2V)."""
    return aero_curves(campaign, altitude_m, [mach])[0]


def aero_curves(campaign: Campaign, altitude_m: float, machs=None) -> list[dict]:
    """``aero_derivatives`` at each of ``machs`` (default: 27 from 0 to the top of the model's Mach axis), the
    nominal rocket built once: the curves of ``rocketmc aero derivatives --plot``."""
    params = nominal_params(campaign)
    aero = params.rocket.aero
    linear = aero if isinstance(aero, LinearAero) else simplify(aero)
    if machs is None:
        machs = np.linspace(0.0, float(np.max(linear.table.axes[linear.table.axis_names.index("mach")])), 27)
    rocket = campaign.config.rocket
    reference_point = rocket.from_nose(rocket.reference_point_m)  # positions below: from the nose tip
    d = float(linear.reference_length_m)
    cg = {when: reference_point - x for when, x in liftoff_and_burnout_cg_x_m(params).items()}
    curves = []
    for mach in machs:
        cp = reference_point - centre_of_pressure_x_m(linear, mach, altitude_m)
        curves.append({
            "model": rocket.aero.model,
            "mach": float(mach),
            "altitude_m": altitude_m,
            "reference_area_m2": float(linear.reference_area_m2),
            "reference_length_m": d,
            "moment_reference_m": reference_point - float(linear.moment_ref_x_m),
            "n_canards": int(linear.n_canards),
            "coefficients_per_rad": linear_derivatives(linear, mach, altitude_m),
            "center_of_pressure_m": cp,
            "center_of_mass_m": cg,
            "static_margin_calibers": {when: (cp - x) / d for when, x in cg.items()},
        })  # fmt: skip
    return curves


def format_aero_derivatives(result: dict) -> str:
    """``aero_derivatives``' result (with the ``rocket`` it names) as a table."""
    c, cp, d = result["coefficients_per_rad"], result["center_of_pressure_m"], result["reference_length_m"]
    lines = [f"{result['rocket']} ({result['model']} model), Mach {result['mach']}, altitude {result['altitude_m']:g} m; "
             f"per rad, moments about {result['moment_reference_m']:.3f} m from the nose, rates per ω·d/(2V)"]  # fmt: skip
    rows = [("CA0", c["CA0"]), ("CNα", c["CNa"]), ("Cmα", c["Cma"]), ("CNq", c["CNq"]), ("Cmq", c["Cmq"]),
            ("Clp", c["Clp"]), ("Cl0", c["Cl0"])]  # fmt: skip
    if result["n_canards"] == 4:
        rows += [("CN_δ (pitch)", c["CN_pitch"]), ("Cm_δ (pitch)", c["Cm_pitch"]), ("Cl_δ (roll)", c["Cl_roll"])]
    lines += [f"  {name:<14}{value:>10.3f}" for name, value in rows]
    lines.append(f"  centre of pressure {cp:.3f} m from the nose tip")
    lines += [f"  {when:<8} CG {x:.3f} m, static margin {(cp - x) / d:.2f} calibers" for when, x in result["center_of_mass_m"].items()]
    return "\n".join(lines)

"""The ranges a campaign's numbers are checked against, each with its reason, and which numbers a campaign
may disperse (docs/conventions.md, Campaign validation)."""

DISPERSIBLE_SECTIONS = ("rocket", "launch", "environment", "gnc", "avionics")
FIXED_PER_CAMPAIGN = ("rocket.reference_point_m", "rocket.nose_position_m", "rocket.geometry.", "rocket.aero.")
"""Numbers that define the body frame or build the aerodynamic tables once per campaign: not
dispersible, except those of ``DISPERSIBLE_AERO``."""
DISPERSIBLE_AERO = ("rocket.aero.drag_scale", "rocket.aero.cl0", "rocket.aero.linear.")
FIXED_GNC = ("gnc.guidance.", "gnc.control.", "gnc.filters.")
"""Guidance, the gain design and the navigation filters' tuning, set once per campaign (the gains are designed
when it loads): not dispersible; the servos (``gnc.servo``) are."""
FIXED_AVIONICS = ("rate_hz", "latency_s", *("_std", "_std_deg"))
"""Ends of the avionics' numbers that are not dispersible: the schedule (rate, latency) is set per campaign,
and the per-flight spreads are dispersions themselves."""
ISP_TOLERANCE = 0.02  # relative mismatch allowed between isp_s and the curve's impulse per propellant mass
SOLID_ISP_S = (60.0, 300.0)
"""Band [s] of the specific impulse a curve's total impulse over its propellant's weight can give a solid motor:
black powder delivers ~80 s and sugar propellants (KNSB) 110-130 s; AP composites 260-265 s at the standard
70:1 bar expansion (Sutton & Biblarz, Rocket Propulsion Elements, composite propellants), the library's highest
270 s (AeroTech K400C's header); outside, the propellant mass is another motor's or a unit slip."""
PROPELLANT_HEADER_TOLERANCE = 0.10
"""A propellant mass further than this (relative) from its ``.eng`` header's is warned of: another motor's (a
casing one grain longer holds 20-35 % more: Cesaroni's Pro75 L1350 2.02 kg, its 4-grain L1395 2.48 kg) or a typo; a modelling choice such as the Lynx thesis's 1.905 kg
for the L1350, the curve's impulse over its measured Isp (5.9 % under the header's 2.0245 kg), is left alone."""

# Physical ranges (docs/conventions.md, Campaign validation): every number is finite and within these, generous
# for any student or amateur rocket, so that a typo or a unit slip is refused here instead of flying a campaign
# of failed flights.
MIN_MASS_KG = 1e-3  # 1 g, below any model rocket: the mass divides every force
MAX_MASS_KG = 5000.0  # a few tonnes: the heaviest amateur rockets weigh under 2 t
MIN_LENGTH_M = 1e-4  # 0.1 mm, thinner than any fin
MAX_LENGTH_M = 100.0  # lengths and positions: amateur rockets are under 20 m long
MAX_DIAMETER_M = 10.0  # diameters: amateur rockets are under 1 m across
MAX_ROUGHNESS_M = 0.01  # surface roughness heights: OpenRocket's roughest finish is 0.5 mm; 1 cm is gravel
MAX_AREA_M2 = 1000.0  # canopy and reference areas: the largest cargo canopies have ~700 m²
MIN_INERTIA_KGM2 = 1e-9  # a 1 g rod 5 mm across has an axial inertia of 3·10⁻⁹ kg·m²; it divides every moment
MAX_INERTIA_KGM2 = 1e7  # a 5 t, 100 m rod about its middle has m·L²/12 ≈ 4·10⁶ kg·m²
MAX_ISP_S = 500.0  # above any chemical motor (hydrogen-oxygen in vacuum: ~450 s)
MAX_SCALE = 10.0  # multipliers of a measured curve (thrust, drag, wind): ×10 is a unit slip, not a dispersion
MAX_DELAY_S = 60.0  # ignition delay, parachute delay and opening time: longer is a flight without that event
MAX_FLIGHT_TIME_S = 3600.0  # a descent under a main canopy from 10 km takes under ~2000 s
MAX_BURN_TIME_S = 100.0  # a reshaped thrust curve: the longest amateur solid motors burn under ~30 s
MAX_ALTITUDE_M = 100_000.0  # heights above ground: the standard atmosphere ends at 47 km (status 4 above)
MAX_WIND_MPS = 150.0  # above the strongest jet-stream winds measured (~110 m/s)
MAX_MACH = 25.0  # Mach axes: beyond any sounding rocket
MAX_AIRBRAKE_PANELS = 16
MAX_AIRBRAKE_MACH = 0.95  # the panels' drag model (stagnation pressure) holds below Mach 1
MAX_AIRBRAKE_RATE_PER_S = 100.0  # full deployment in 10 ms
MAX_AIRBRAKE_GAIN = 1.0  # K_i [1/(m·s)]: full deployment per second for a 1 m predicted error
MAX_AIRBRAKE_PI_GAIN = 1e5  # K_p [N/(m/s)], K_i [N/m]: 100 kN for 1 m/s off the reference (Skyward's: 55, 50)
MAX_AIRBRAKE_NATURAL_FREQUENCY_RAD_S = 20.0  # the servo's 0.1 s lag bounds what a brake loop can follow
MAX_AIRBRAKE_REFERENCES = 32
MAX_AIRBRAKE_DAMPING = 10.0  # ζ: far past critical (1)
MAX_DRAG_COEFFICIENT = 10.0  # axial-force and canopy coefficients: a flat plate's is 1.2, a canopy's 0.8-2.2
MAX_COEFFICIENT = 1000.0  # static derivatives and offsets [per rad]: 40 × Lynx's CNα (24 per rad)
MAX_DAMPING_COEFFICIENT = 1e5  # damping derivatives [per ω·d/(2V)]: 50 × Lynx's Cmq (−1813)
MIN_CONTROL_DT_S = 1e-3  # 1 kHz, the fastest flight-computer loops; a flight is max_time_s/control_dt_s periods
MAX_REALIZATIONS = 10**8  # ~20 float64 outputs per flight: 10⁸ flights fill ~16 GB
MAX_NAME_LENGTH = 128  # a campaign's name is a label, printed and stored in result files
MAX_SPEED_MPS = 10_000.0  # speeds: Mach 25 (MAX_MACH) is ~8.5 km/s
MAX_SERVO_TIME_CONSTANT_S = 1.0  # a servo slower than 1 s cannot follow a ~10 s guidance window (Lynx: 0.077 s)
MAX_CANARD_LIMIT_DEG = 45.0  # canards stall beyond ~20°: 45° is a unit slip, not a servo
MAX_SERVO_RATE_DEG_S = 10_000.0  # servos slew 60-1000 °/s
MAX_RATE_DEG_S = 3600.0  # commanded body rates: ten turns a second is no guidance
MAX_GUIDANCE_GAIN = 1000.0  # guidance [1/s] and integrator [-] gains: 200 × the thesis's; k·T ≫ 1 oscillates
MAX_WIND_GAIN = 100.0
"""Guidance's upwind aim [-]: the reference's horizontal speed moved by k_w × the wind; Lynx's is ~19 m/s, so 100
turns a 1 m/s wind into a reference 80° off its heading: beyond, the aim no longer points where the rocket goes."""
MAX_SENSOR_VALUE = 1e7  # any sensor's unit (m/s², deg/s, µT, Pa, deg): 1e7 Pa is 100 atmospheres
MAX_SENSOR_LATENCY_S = 1.0  # a sensor later than a second is a logger, not a GNC input
MAX_MISALIGNMENT_DEG = 10.0  # a sensor more than 10° off its mount is mounted elsewhere
MAX_ANOMALY_NT = 100_000.0  # twice the main field: the strongest crustal anomalies (iron ores) reach ~tens of µT
MAX_SOFT_IRON_STD = 0.5  # a soft-iron matrix half off the identity per flight is no calibration
MAX_LENGTH_KM = 100.0  # GNSS errors: 100 km is no fix
MAX_LQ_WEIGHT = 1e12  # LQI weights: only their ratios matter, and the DARE loses accuracy beyond 1e12 apart
DEFAULT_SPEEDS_MPS = [20.0, 30.0, 40.0, 60.0, 80.0, 100.0, 150.0, 200.0, 250.0, 300.0]
DEFAULT_ALTITUDES_M = [0.0, 1000.0, 2000.0]
"""The default design grid [m/s] × [m above the pad]. Lynx's guidance window (1-10 s after liftoff, at
Roccaraso) flies 62-183 m/s and 30-1220 m (``campaign/gains.py``' estimate), from its rail exit at 21 m/s
when it opens at liftoff; the grid adds room for dispersions and winds. Interpolated linearly, these
points give the main gains of Lynx's designs in between within 5 % (closer where the gains vary less
than the ~1/u of K_p below 40 m/s), and within 0.1 % between these altitudes."""
NORMAL_REACH_STD = 6.0
"""An unclipped side of a normal dispersion is checked at mean ± 6·std: a draw beyond has a
probability of ~1e-9."""

MAX_GATE = 1e4  # a χ² gate of 1e4 on the normalised innovation squared is a 100σ gate: none at all
MAX_SLOW_FACTOR = 100.0  # a servo 100× slower than Lynx's (0.077 s → 7.7 s) no longer moves in the window: stuck
MAX_FIELD_STEP_UT = 10_000.0  # 200 × the geomagnetic field: a motor's current (~100 A at ~10 cm) makes ~200 µT
GEOMETRY_TOLERANCE_M = 1e-9
"""Slack on the geometry's fits [m]: a fin whose trailing edge is the aft end, computed from positions in
another origin, may land a rounding error past it."""


def fixed_reason(path: str) -> str | None:
    """Why the number at dotted ``path`` is fixed for the whole campaign (not dispersible), or None."""
    if path.startswith(FIXED_PER_CAMPAIGN) and not path.startswith(DISPERSIBLE_AERO):
        return ("fixed for the whole campaign (it defines the body frame or builds the aerodynamic tables); "
                "disperse rocket.aero.drag_scale or rocket.aero.cl0 instead")  # fmt: skip
    if path.startswith("avionics.") and path.rstrip("0123456789.").endswith(FIXED_AVIONICS):
        return "fixed for the whole campaign (a sensor's schedule is set once, and its per-flight spreads are dispersions already)"
    if path.startswith(FIXED_GNC):
        return ("fixed for the whole campaign (guidance, the LQI gains and the navigation filters are set once, "
                "when it loads); only the servos, gnc.servo.*, can be dispersed")  # fmt: skip
    return None

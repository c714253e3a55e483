"""rocketmc import: an OpenRocket design read, checked against hand computation, written as a campaign that loads;
each refusal one line naming the component, with no file written. The fixtures are this project's own small
designs, built here (OpenRocket's examples are GPL and stay out of the repository)."""

from __future__ import annotations

import math
import zipfile

import pytest

from rocketmc.campaign import load_campaign
from rocketmc.campaign import openrocket_mass as om
from rocketmc.campaign.openrocket import OpenRocketError, read_design, read_simulation, stored_dry_mass
from rocketmc.campaign.openrocket_campaign import import_openrocket
from rocketmc.cli import main
from rocketmc.dynamics.motor_library import find_motor
from rocketmc.dynamics.rigid_body import MassProperties, combine_on_axis

CARDBOARD = 680.0  # kg/m³
R, WALL = 0.025, 0.001  # body radius and wall [m]
NOSE_L, NOSE_T, PLASTIC = 0.12, 0.002, 1050.0  # conical nose: length, wall [m], density [kg/m³]
TUBE_L = 0.4
FIN_C, FIN_S, FIN_T = 0.05, 0.04, 0.002  # rectangular fins: chord, span, thickness [m]
LUG_R, LUG_T, LUG_L = 0.0035, 0.001, 0.035
MOUNT_R, MOUNT_T, MOUNT_L, OVERHANG = 0.0095, 0.0005, 0.075, 0.003
RING_L = 0.004
CHUTE_D, NYLON, LINES, LINE_L, CORD = 0.3, 0.067, 6, 0.3, 0.0018  # canopy [m, kg/m²], lines [count, m, kg/m]
PACK_L, PACK_R = 0.04, 0.009
BALLAST_KG, BALLAST_L, BALLAST_R, BALLAST_AT = 0.01, 0.02, 0.01, 0.15  # a mass component placed absolutely
MOTOR_D, MOTOR_L, MOTOR_KG, PROPELLANT_KG = 0.018, 0.07, 0.016, 0.0062

REL_SLICING = 1e-4
"""The nose shell is integrated over 2000 slices (midpoint rule): its error on the cone's mass and moments is ~1e-6
relative; 1e-4 leaves room without hiding a wrong wall or a misplaced part (those move the figures by > 1 %)."""


def _component(tag: str, name: str, body: str, method: str | None = None, offset: float = 0.0,
               children: str = "") -> str:
    place = f'<axialoffset method="{method}">{offset}</axialoffset>' if method else ""
    subs = f"<subcomponents>{children}</subcomponents>" if children else ""
    return f"<{tag}><name>{name}</name>{place}{body}{subs}</{tag}>"


def _material(density: float, tag: str = "material", kind: str = "bulk") -> str:
    return f'<{tag} type="{kind}" density="{density}">stuff</{tag}>'


def nose() -> str:
    return _component("nosecone", "Nose", f"{_material(PLASTIC)}<length>{NOSE_L}</length><thickness>{NOSE_T}"
                      f"</thickness><shape>conical</shape><aftradius>auto</aftradius>")  # fmt: skip


def fins(kind: str = "trapezoidfinset") -> str:
    shape = (f"<rootchord>{FIN_C}</rootchord><tipchord>{FIN_C}</tipchord><sweeplength>0.0</sweeplength>"
             f"<height>{FIN_S}</height>") if kind == "trapezoidfinset" else \
        f"<rootchord>{FIN_C}</rootchord><height>{FIN_S}</height>"  # fmt: skip
    return _component(kind, "Fins", f"<fincount>3</fincount>{_material(CARDBOARD)}<thickness>{FIN_T}</thickness>"
                      f"<crosssection>square</crosssection><cant>0.0</cant>{shape}", "bottom", 0.0)  # fmt: skip


def mount(cluster: str = "single") -> str:
    motor = (f'<motormount><overhang>{OVERHANG}</overhang><motor configid="c1"><manufacturer>Acme</manufacturer>'
             f"<designation>X1</designation><diameter>{MOTOR_D}</diameter><length>{MOTOR_L}</length>"
             f"<delay>2.0</delay></motor></motormount>")  # fmt: skip
    return _component("innertube", "Motor tube", f"{_material(CARDBOARD)}<length>{MOUNT_L}</length><outerradius>"
                      f"{MOUNT_R}</outerradius><thickness>{MOUNT_T}</thickness><clusterconfiguration>{cluster}"
                      f"</clusterconfiguration>{motor}", "bottom", 0.0)  # fmt: skip


def tube_parts(extra: str = "") -> str:
    ring = _component("centeringring", "Ring", f"{_material(CARDBOARD)}<length>{RING_L}</length><outerradius>auto"
                      "</outerradius><innerradius>auto</innerradius>", "bottom", -0.02)  # fmt: skip
    lug = _component("launchlug", "Lug", f"{_material(CARDBOARD)}<radius>{LUG_R}</radius><thickness>{LUG_T}"
                     f"</thickness><length>{LUG_L}</length>", "middle", 0.0)  # fmt: skip
    chute = _component("parachute", "Main chute", f"{_material(NYLON, kind='surface')}<cd>auto</cd><deployevent>"
                       f"altitude</deployevent><deployaltitude>150</deployaltitude><deploydelay>0.5</deploydelay>"
                       f"<diameter>{CHUTE_D}</diameter><linecount>{LINES}</linecount><linelength>{LINE_L}"
                       f"</linelength>{_material(CORD, 'linematerial', 'line')}<packedlength>{PACK_L}</packedlength>"
                       f"<packedradius>{PACK_R}</packedradius>", "top", 0.03)  # fmt: skip
    ballast = _component("masscomponent", "Ballast", f"<mass>{BALLAST_KG}</mass><packedlength>{BALLAST_L}"
                         f"</packedlength><packedradius>{BALLAST_R}</packedradius>", "absolute", BALLAST_AT)  # fmt: skip
    return fins() + ring + lug + chute + ballast + mount() + extra


def body_tube(children: str | None = None) -> str:
    return _component("bodytube", "Body", f"{_material(CARDBOARD)}<length>{TUBE_L}</length><thickness>{WALL}"
                      f"</thickness><radius>{R}</radius>", children=tube_parts() if children is None else children)


def simulation_xml() -> str:
    """A stored flight whose t = 0 mass and CG are the fixture's closed forms plus the motor (``expected``)."""
    dry, motor = expected(), motor_body()
    total = combine_on_axis([tuple(dry), tuple(motor)])
    rows = [(0.0, 0.0, 0.0, total.mass, MOTOR_KG, total.cg_x), (0.1, 1.0, 10.0, total.mass - 0.003, MOTOR_KG - 0.003,
            total.cg_x), (0.5, 20.0, 8.0, total.mass - PROPELLANT_KG, MOTOR_KG - PROPELLANT_KG, total.cg_x),
            (0.6, 30.0, 0.0, total.mass - PROPELLANT_KG, MOTOR_KG - PROPELLANT_KG, total.cg_x)]  # fmt: skip
    points = "".join(f"<datapoint>{','.join(repr(v) for v in row)}</datapoint>" for row in rows)
    return ("<simulations><simulation><name>Calm day</name><conditions><configid>c1</configid>"
            "<launchrodlength>1.5</launchrodlength><launchintowind>false</launchintowind><launchrodangle>5.0"
            "</launchrodangle><launchroddirection>45.0</launchroddirection><windaverage>3.0</windaverage>"
            "<windturbulence>0.1</windturbulence><winddirection>1.5707963267948966</winddirection>"
            "<windmodeltype>Average</windmodeltype><launchaltitude>120.0</launchaltitude><launchlatitude>45.5"
            '</launchlatitude><launchlongitude>9.2</launchlongitude><atmosphere model="isa"/></conditions>'
            '<flightdata maxaltitude="30.0" timetoapogee="0.6"><databranch name="Sustainer" '
            'types="Time,Altitude,Thrust,Mass,Motor mass,CG location"><event time="0" type="ignition"/>'
            '<event time="0.5" type="burnout"/><event time="0.6" type="apogee"/>'
            f"{points}</databranch></flightdata></simulation></simulations>")  # fmt: skip


def design_xml(stage: str | None = None, extra_stage: str = "", simulations: str | None = None,
               version: str = "1.10") -> str:
    stage = nose() + body_tube() if stage is None else stage
    return (f'<?xml version="1.0"?><openrocket version="{version}"><rocket><name>Test rocket</name><subcomponents>'
            f"<stage><name>Sustainer</name><subcomponents>{stage}</subcomponents></stage>{extra_stage}"
            f"</subcomponents></rocket>{simulation_xml() if simulations is None else simulations}</openrocket>")


def write_ork(folder, xml: str, name: str = "test.ork"):
    path = folder / name
    with zipfile.ZipFile(path, "w") as archive:
        archive.writestr("rocket.ork", xml)
    return path


# Closed forms of the fixture, from the nose tip [m].

def cone_shell() -> MassProperties:
    """A conical nose with a wall NOSE_T thick normal to its surface: the solid cone less the inner cone, whose apex
    is t/sin θ behind the tip."""
    theta = math.atan(R / NOSE_L)
    apex = NOSE_T / math.sin(theta)
    inner_h, inner_r = NOSE_L - apex, (NOSE_L - apex) * math.tan(theta)
    cones = []
    for sign, h, r, x0 in ((1, NOSE_L, R, 0.0), (-1, inner_h, inner_r, apex)):
        m = sign * PLASTIC * math.pi * r**2 * h / 3
        cones.append((m, x0 + 0.75 * h, 0.3 * m * r**2, m * (3 * r**2 / 20 + 3 * h**2 / 80)))
    return combine_on_axis(cones)


def tube_closed(ro: float, ri: float, length: float, top: float, density: float = CARDBOARD) -> tuple:
    m = density * math.pi * (ro**2 - ri**2) * length
    return m, top + length / 2, m * (ro**2 + ri**2) / 2, m * (3 * (ro**2 + ri**2) + length**2) / 12


def expected() -> MassProperties:
    """The fixture's dry mass, CG and inertia by hand: each part in closed form, then parallel axes."""
    aft = NOSE_L + TUBE_L
    fin_m = 3 * CARDBOARD * FIN_T * FIN_C * FIN_S
    radial_sq = R**2 + R * FIN_S + FIN_S**2 / 3  # mean of (R + y)² over the rectangle
    fins_part = (fin_m, aft - FIN_C / 2, fin_m * radial_sq, fin_m * (FIN_C**2 / 12 + radial_sq / 2))
    chute_m = NYLON * math.pi * CHUTE_D**2 / 4 + LINES * LINE_L * CORD
    mass_objects = [(m, top + length / 2, m * r**2 / 2, m * (3 * r**2 + length**2) / 12)
                    for m, top, length, r in ((chute_m, NOSE_L + 0.03, PACK_L, PACK_R),
                                              (BALLAST_KG, BALLAST_AT, BALLAST_L, BALLAST_R))]  # fmt: skip
    return combine_on_axis([
        tuple(cone_shell()),
        tube_closed(R, R - WALL, TUBE_L, NOSE_L),
        fins_part,
        tube_closed(R - WALL, MOUNT_R, RING_L, aft - 0.02 - RING_L),  # auto radii: the body's inside, the mount
        tube_closed(LUG_R, LUG_R - LUG_T, LUG_L, NOSE_L + (TUBE_L - LUG_L) / 2),
        tube_closed(MOUNT_R, MOUNT_R - MOUNT_T, MOUNT_L, aft - MOUNT_L),
        *mass_objects,
    ])  # fmt: skip


def motor_body() -> MassProperties:
    """The motor as OpenRocket models it: a solid cylinder, its aft end the mount's plus the overhang."""
    top = NOSE_L + TUBE_L + OVERHANG - MOTOR_L
    r = MOTOR_D / 2
    return MassProperties(MOTOR_KG, top + MOTOR_L / 2, MOTOR_KG * r**2 / 2, MOTOR_KG * (3 * r**2 + MOTOR_L**2) / 12)


def test_the_conical_shell_against_its_closed_form():
    shell = om.shell_of_revolution(lambda x: R * x / NOSE_L, NOSE_L, NOSE_T, PLASTIC)
    assert shell == pytest.approx(cone_shell(), rel=REL_SLICING)


def test_a_tube_is_pi_ro2_ri2_l_rho_with_its_inertia():
    part = om.tube(0.05, 0.048, 0.3, 1000.0)
    assert part == pytest.approx(tube_closed(0.05, 0.048, 0.3, 0.0, 1000.0), rel=1e-12)  # the same formula: rounding


def test_positions_and_geometry_by_hand(tmp_path):
    design = read_design(write_ork(tmp_path, design_xml()))
    assert (design.nose_kind, design.nose_length_m, design.body_diameter_m) == ("conical", NOSE_L, 2 * R)
    assert design.length_m == pytest.approx(NOSE_L + TUBE_L, abs=1e-12)  # sums of the lengths: rounding only
    fin_set = design.fins[0].shape
    assert (fin_set.count, fin_set.root_chord_m, fin_set.tip_chord_m, fin_set.span_m) == (3, FIN_C, FIN_C, FIN_S)
    assert fin_set.position_m == pytest.approx(NOSE_L + TUBE_L - FIN_C, abs=1e-12)  # "bottom": aft ends flush
    assert design.lugs == [("Lug", pytest.approx(NOSE_L + (TUBE_L + LUG_L) / 2, abs=1e-12))]  # "middle", aft end
    (chute,) = design.recovery
    assert (chute.cd, chute.event, chute.altitude_m, chute.delay_s) == (0.8, "altitude", 150.0, 0.5)
    assert chute.attach_m == pytest.approx(NOSE_L + 0.03 + PACK_L / 2, abs=1e-12)  # "top" + half the packed length
    motor = design.motor_mount("c1")
    assert motor.nozzle_m == pytest.approx(NOSE_L + TUBE_L + OVERHANG, abs=1e-12)
    assert motor.top_m == pytest.approx(NOSE_L + TUBE_L + OVERHANG - MOTOR_L, abs=1e-12)


def test_mass_cg_and_inertia_against_closed_forms(tmp_path):
    design = read_design(write_ork(tmp_path, design_xml()))
    assert design.dry == pytest.approx(expected(), rel=REL_SLICING)
    assert design.parts == 8  # nose, body, fins, ring, lug, parachute, ballast, motor tube


def test_the_stored_t0_mass_less_the_motor_gives_back_the_rocket(tmp_path):
    design = read_design(write_ork(tmp_path, design_xml()))
    sim = read_simulation(design, None)
    stored = stored_dry_mass(sim, design.motor_mount(sim.config_id))
    # the fixture stores the closed forms plus the motor (no inertia columns): the subtraction returns them to rounding
    assert stored.mass == pytest.approx(expected().mass, rel=1e-12)
    assert stored.cg_x == pytest.approx(expected().cg_x, rel=1e-12)


def test_overrides_of_mass_and_cg(tmp_path):
    overridden = body_tube().replace("<radius>", "<overridemass>0.5</overridemass><overridesubcomponentsmass>true"
                                     "</overridesubcomponentsmass><overridecg>0.1</overridecg><radius>", 1)  # fmt: skip
    design = read_design(write_ork(tmp_path, design_xml(stage=nose() + overridden)))
    nose_part = cone_shell()
    assert design.dry.mass == pytest.approx(nose_part.mass + 0.5, rel=REL_SLICING)
    cg = (nose_part.mass * nose_part.cg_x + 0.5 * (NOSE_L + 0.1)) / (nose_part.mass + 0.5)  # the tube's CG moved
    assert design.dry.cg_x == pytest.approx(cg, rel=REL_SLICING)


def test_elliptical_fins_become_the_trapezoid_of_the_same_span_chord_area_and_centroid(tmp_path):
    stage = nose() + body_tube(fins("ellipticalfinset") + mount())
    design = read_design(write_ork(tmp_path, design_xml(stage=stage)))
    fin_set = design.fins[0].shape
    # half an ellipse: area π c s / 4, centroid at mid-chord; the trapezoid: tip = c(π/2 − 1), centred sweep
    assert fin_set.tip_chord_m == pytest.approx(FIN_C * (math.pi / 2 - 1), rel=1e-4)  # the 200-point polygon
    assert fin_set.sweep_m == pytest.approx((FIN_C - fin_set.tip_chord_m) / 2, abs=1e-6)
    assert "elliptical fins flown as the trapezoid" in design.warnings[0]


def test_the_written_campaign_loads_with_its_sources(tmp_path):
    out = tmp_path / "imported.toml"
    result = import_openrocket(write_ork(tmp_path, design_xml()), out)
    campaign = load_campaign(out)
    rocket = campaign.config.rocket
    assert rocket.dry_mass_kg == pytest.approx(expected().mass, rel=REL_SLICING)
    assert rocket.motor.propellant_mass_kg == pytest.approx(PROPELLANT_KG, rel=1e-9)  # Motor mass 0 s less 0.5 s
    assert rocket.motor.dry_mass_kg == pytest.approx(MOTOR_KG - PROPELLANT_KG, rel=1e-9)
    assert rocket.rear_lug_m == pytest.approx(NOSE_L + (TUBE_L + LUG_L) / 2, rel=1e-6)  # written to 7 digits
    assert rocket.parachutes[0].name == "main_chute" and rocket.parachutes[0].deploy_altitude_m == 150.0
    launch = campaign.config.launch
    assert (launch.rail_length_m, launch.elevation_deg, launch.azimuth_deg) == (1.5, 85.0, 45.0)
    layer = campaign.config.environment.wind.layers[0]
    assert (layer.speed_mps, layer.from_deg) == (3.0, 90.0)
    assert campaign.config.site.altitude_m == 120.0
    assert list(campaign.thrust_n) == [0.0, 10.0, 8.0]  # the Thrust column to burnout
    text = out.read_text()
    assert "# 'Fins'" in text and "stored simulation 1 ('Calm day')" in text and "computed from 8 components" in text
    assert result.thrust_curve.read_text().startswith("time_s,thrust_n\n")


def test_two_rail_buttons_are_written_as_the_rear_and_the_upper_lug(tmp_path):
    """Two rail buttons 0.25 m apart: rear_lug_m the aft one, upper_lug_m the forward one, whose passing the rail's
    top frees the rocket (a button: its centre)."""
    buttons = _component("railbutton", "Buttons", f"{_material(PLASTIC)}<instancecount>2</instancecount>"
                         "<instanceseparation>0.25</instanceseparation><outerdiameter>0.01</outerdiameter>"
                         "<innerdiameter>0.006</innerdiameter><height>0.008</height>", "top", 0.1)  # fmt: skip
    stage = nose() + body_tube(fins() + buttons + mount())
    out = tmp_path / "buttons.toml"
    import_openrocket(write_ork(tmp_path, design_xml(stage=stage)), out)
    rocket = load_campaign(out).config.rocket
    assert rocket.upper_lug_m == pytest.approx(NOSE_L + 0.1, rel=1e-6)  # written to 7 digits
    assert rocket.rear_lug_m == pytest.approx(NOSE_L + 0.35, rel=1e-6)
    assert "the rocket leaves the rail when it passes the top" in out.read_text()


def test_a_motor_of_the_library_by_designation(tmp_path):
    """``--motor NAME``: the library's motor named in the campaign (no thrust file written), its curve, header
    propellant and casing the library's, the rocket's dry mass still without the motor; the design's own motor when
    the library has it; an unknown name: one line with the close matches and nothing written."""
    ork = write_ork(tmp_path, design_xml())
    result = import_openrocket(ork, tmp_path / "named.toml", motor="k1000t")
    assert result.thrust_curve is None and sorted(p.name for p in tmp_path.iterdir()) == ["named.toml", "test.ork"]
    entry = find_motor("K1000T")
    rocket = load_campaign(tmp_path / "named.toml").config.rocket
    assert rocket.motor.designation == entry.designation and rocket.motor.thrust_curve is None
    assert (rocket.motor.propellant_mass_kg, rocket.motor.dry_mass_kg) == (entry.propellant_mass_kg, entry.casing_mass_kg)
    assert rocket.dry_mass_kg == pytest.approx(expected().mass, rel=REL_SLICING)
    own = write_ork(tmp_path, design_xml().replace("<designation>X1</designation>", "<designation>K1000T</designation>"),
                    "own.ork")  # fmt: skip
    result = import_openrocket(own, tmp_path / "own.toml")
    assert "motor K1000T-P from the library" in result.lines[0] and result.thrust_curve is None
    with pytest.raises(OpenRocketError, match=r"^--motor K1000Z: .*K1000T"):
        import_openrocket(ork, tmp_path / "unknown.toml", motor="K1000Z")
    assert not (tmp_path / "unknown.toml").exists()


@pytest.mark.parametrize("case, named", [
    ("pod", "'Pods' (podset)"),
    ("cluster", "'Motor tube' (innertube): a motor cluster"),
    ("second stage", "'Booster' (stage): a second stage"),
    ("tube fins", "'Tubes' (tubefinset)"),
    ("no simulation", "no simulation and its motor 'X1' is not in rocketmc's library"),
    ("corrupt zip", "a corrupt zip"),
    ("no rocket.ork", "a zip without rocket.ork"),
    ("malformed xml", "malformed XML"),
    ("version", "file version '2.0' is not supported"),
])  # fmt: skip
def test_each_refusal_is_one_line_naming_the_component_and_writes_nothing(tmp_path, case, named):
    pod = _component("podset", "Pods", "", "top", 0.0)
    xml = {
        "pod": lambda: design_xml(stage=nose() + body_tube(tube_parts(pod))),
        "cluster": lambda: design_xml(stage=nose() + body_tube(mount("4-ring"))),
        "second stage": lambda: design_xml(extra_stage=f"<stage><name>Booster</name><subcomponents>{body_tube()}"
                                                       "</subcomponents></stage>"),  # fmt: skip
        "tube fins": lambda: design_xml(stage=nose() + body_tube(tube_parts(_component("tubefinset", "Tubes", "")))),
        "no simulation": lambda: design_xml(simulations=""),
        "malformed xml": lambda: design_xml()[:-20],
        "version": lambda: design_xml(version="2.0"),
    }.get(case)
    if case == "corrupt zip":
        path = tmp_path / "test.ork"
        path.write_bytes(b"PK\x03\x04 not really a zip")
    elif case == "no rocket.ork":
        path = tmp_path / "test.ork"
        with zipfile.ZipFile(path, "w") as archive:
            archive.writestr("notes.txt", "hello")
    else:
        path = write_ork(tmp_path, xml())
    out = tmp_path / "out" / "campaign.toml"
    out.parent.mkdir()
    with pytest.raises(OpenRocketError) as refusal:
        import_openrocket(path, out)
    message = str(refusal.value)
    assert "\n" not in message and named in message, message
    assert list(out.parent.iterdir()) == []


def test_transitions_lugs_buttons_and_finishes_are_written(tmp_path):
    """A widening shoulder, a wider tube and an aft narrowing transition: the shoulder and the tail become conical
    sections (the tail narrows from the wider tube, not from the nose's diameter: no boat-tail); the lug, the rail button, the finishes (OpenRocket's roughness
    heights) and the fins' square cross-section reach the campaign. Positions are sums of the fixture's lengths:
    1e-12 m is their rounding."""
    shoulder = _component("transition", "Shoulder", f"{_material(PLASTIC)}<length>0.05</length><thickness>0.001"
                          f"</thickness><shape>conical</shape><foreradius>{R}</foreradius><aftradius>{1.2 * R}"
                          "</aftradius><finish>rough</finish>")  # fmt: skip
    button = _component("railbutton", "Button", f"{_material(PLASTIC)}<outerdiameter>0.01</outerdiameter>"
                        "<innerdiameter>0.006</innerdiameter><height>0.008</height><baseheight>0.002</baseheight>"
                        "<flangeheight>0.002</flangeheight><instancecount>2</instancecount><instanceseparation>0.1"
                        "</instanceseparation>", "top", 0.05)  # fmt: skip
    wide = body_tube(tube_parts(button)).replace("<name>Body</name>", "<name>Wide</name>").replace(
        f"<radius>{R}</radius>", f"<radius>{1.2 * R}</radius><finish>polished</finish>")
    tail = _component("transition", "Tail", f"{_material(PLASTIC)}<length>0.03</length><thickness>0.001</thickness>"
                      f"<shape>conical</shape><foreradius>{1.2 * R}</foreradius><aftradius>{R}</aftradius>")  # fmt: skip
    front = _component("bodytube", "Front", f"{_material(CARDBOARD)}<length>0.1</length><thickness>{WALL}"
                       f"</thickness><radius>{R}</radius><finish>normal</finish>")  # fmt: skip
    ork = write_ork(tmp_path, design_xml(stage=nose() + front + shoulder + wide + tail))
    design = read_design(ork)
    top = NOSE_L + 0.1
    assert [name for name, _ in design.transitions] == ["Shoulder", "Tail"] and design.boat_tail is None
    t = design.transitions[0][1]
    assert (t.position_m, t.length_m, t.fore_diameter_m, t.aft_diameter_m) == pytest.approx(
        (top, 0.05, 2 * R, 2.4 * R), abs=1e-12)
    assert design.transitions[1][1].position_m == pytest.approx(top + 0.05 + TUBE_L, abs=1e-12)
    result = import_openrocket(ork, tmp_path / "steps.toml")
    geometry = load_campaign(result.campaign).config.rocket.geometry
    assert geometry.surface_roughness_m == 2e-6  # the wide tube, polished, is the largest surface
    assert any("finishes" in w for w in result.warnings)
    diameters = [d for t in geometry.transitions for d in (t.fore_diameter_m, t.aft_diameter_m)]
    assert diameters == pytest.approx([2 * R, 2.4 * R, 2.4 * R, 2 * R], rel=1e-6)  # 7 digits written
    (lug,) = geometry.launch_lugs
    assert (lug.outer_diameter_m, lug.inner_diameter_m, lug.length_m) == pytest.approx(
        (2 * LUG_R, 2 * (LUG_R - LUG_T), LUG_L), rel=1e-6)
    assert [b.position_m for b in geometry.rail_buttons] == pytest.approx([top + 0.1, top + 0.2], rel=1e-6)
    assert (geometry.rail_buttons[0].height_m, geometry.rail_buttons[0].inner_height_m) == pytest.approx((0.008, 0.004))
    assert geometry.fins[0].profile == "square" and geometry.fins[0].surface_roughness_m == 60e-6  # "normal" default


def test_a_transition_whose_drag_openrocket_overrides_keeps_it(tmp_path):
    """OpenRocket's "base drag hack": a cone from a point to the body's diameter behind the tube, its drag
    overridden to 0: written as a section with cd_override = 0 (not a boat-tail, not warned of), and the campaign
    flies the override; a body tube's override is still warned of (rocketmc computes the body's drag whole)."""
    hack = _component("transition", "Hack", f"{_material(PLASTIC)}<overridecd>0.0</overridecd><length>0.1</length>"
                      f"<thickness>0.0001</thickness><shape>conical</shape><foreradius>0.00001</foreradius>"
                      f"<aftradius>{R}</aftradius>")  # fmt: skip
    ork = write_ork(tmp_path, design_xml(stage=nose() + body_tube() + hack))
    design = read_design(ork)
    ((name, section),) = design.transitions
    assert name == "Hack" and section.cd_override == 0.0 and design.boat_tail is None
    assert not any("drag override" in w for w in design.warnings)
    result = import_openrocket(ork, tmp_path / "hack.toml")
    (written,) = load_campaign(result.campaign).config.rocket.geometry.transitions
    assert written.cd_override == 0.0
    overridden_tube = body_tube().replace("<name>Body</name>", "<name>Body</name><overridecd>0.3</overridecd>")
    assert any("'Body': its drag override" in w for w in read_design(write_ork(
        tmp_path, design_xml(stage=nose() + overridden_tube), "tube.ork")).warnings)


def test_a_bare_rocket_ork_xml_is_read_too(tmp_path):
    path = tmp_path / "rocket.ork"
    path.write_text(design_xml())
    assert read_design(path).dry == pytest.approx(expected(), rel=REL_SLICING)


def test_cli_imports_and_refuses_with_exit_code_2(tmp_path, capsys):
    ork = write_ork(tmp_path, design_xml())
    out = tmp_path / "rocket.toml"
    assert main(["import", str(ork), "--out", str(out)]) == 0
    printed = capsys.readouterr()
    assert "Test rocket" in printed.out and "wrote" in printed.out and out.is_file()
    assert main(["import", str(ork), "--out", str(out)]) == 2  # exists, no --force
    error = capsys.readouterr().err
    assert error.startswith("rocketmc: error:") and error.count("\n") == 1 and "--force" in error
    assert main(["import", str(ork), "--out", str(out), "--force"]) == 0
    capsys.readouterr()
    bad = write_ork(tmp_path, design_xml(stage=nose() + body_tube(mount("3-ring"))), "cluster.ork")
    assert main(["import", str(bad), "--out", str(tmp_path / "cluster.toml")]) == 2
    error = capsys.readouterr().err
    assert error.count("\n") == 1 and "'Motor tube'" in error and not (tmp_path / "cluster.toml").exists()

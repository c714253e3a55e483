"""OpenRocket designs read in rocketmc's terms (host side): a ``.ork`` file (a zip holding ``rocket.ork``, or that XML
bare) becomes a ``Design``: the body profile, fin sets, lugs, recovery devices and motor mount placed from the nose
tip (positions [m], growing aft), the dry mass, CG and inertia computed from the components, and the simulations
with their stored flight data. What rocketmc cannot fly is refused in one line naming the OpenRocket component.

Positions follow OpenRocket's rules: a body component (nose cone, body tube, transition) comes after the one before
it; any other is placed against its parent by ``<axialoffset method=...>`` (older files: ``<position type=...>``):
``top`` (front ends), ``middle`` (centres), ``bottom`` (aft ends), ``after`` (after the previous sibling) or
``absolute`` (from the nose tip). Masses are OpenRocket's: material density × volume (a shell of revolution for
nose cones and transitions, tubes and rings, flat fins with their tabs), the given mass of mass components,
parachutes from canopy area and lines, cords from their length, and the mass and CG overrides with their
``overridesubcomponents`` flags (``campaign.openrocket_mass``). The writer is ``campaign.openrocket_campaign``.
"""

from __future__ import annotations

import dataclasses
import math
import zipfile
from pathlib import Path
from xml.etree import ElementTree

import numpy as np

from ..aero.drag import OPENROCKET_FINISHES_M
from ..aero.geometry import FinSet, LaunchLug, RailButton, Transition, nose_radius_m
from ..dynamics.rigid_body import MassProperties
from . import openrocket_mass as om
from .errors import ConfigError

SUPPORTED_VERSIONS = tuple(f"1.{minor}" for minor in range(12))
"""The file versions OpenRocket (24.12 and the development version) reads and writes: 1.0 to 1.11."""
BODY_KINDS = ("nosecone", "bodytube", "transition")
"""The components that make the outer body, one after the other."""
MASS_OBJECTS = ("parachute", "streamer", "shockcord", "masscomponent")
RINGS = ("innertube", "tubecoupler", "centeringring", "bulkhead", "engineblock", "launchlug")
FIN_SETS = ("trapezoidfinset", "ellipticalfinset", "freeformfinset")
ASSEMBLIES = ("stage",)
REFUSED = {
    "podset": "a pod set (rocketmc flies one body on one axis)",
    "parallelstage": "a parallel stage, boosters beside the body (rocketmc flies one body on one axis)",
    "tubefinset": "tube fins (rocketmc's fins are flat trapezoidal panels)",
}
"""Components rocketmc cannot fly, and why."""
NOSE_SHAPES = {("conical", None): "conical", ("ogive", 1.0): "ogive", ("ogive", 0.0): "conical",
               ("ellipsoid", None): "elliptical", ("parabolic", 1.0): "parabolic", ("parabolic", 0.0): "conical",
               ("haack", 0.0): "von_karman", ("haack", 1 / 3): "haack_lv", ("power", 1.0): "conical"}  # fmt: skip
"""OpenRocket's nose shape and shape parameter (None: any) → rocketmc's ``NOSE_KINDS``, the profiles being the same."""
SHAPE_PARAMETER_TOLERANCE = 1e-3
"""How close a shape parameter must be to a mapped one (OpenRocket's own tolerance for its cases is 1e-5; its
files write the parameter rounded to several digits)."""
RADIUS_TOLERANCE_M = 1e-4
"""Two radii closer than this are one body diameter (0.1 mm: OpenRocket rounds imperial tubes to the micrometre)."""
CROSS_SECTIONS = {"square": 1.0, "rounded": 0.99, "airfoil": 0.85}
"""A fin's volume over planform area × thickness, by cross-section (OpenRocket's factors)."""
PARACHUTE_CD = 0.8
"""OpenRocket's drag coefficient of a parachute whose Cd is "auto"."""
STREAMER_MAX_CD = 0.4
"""OpenRocket's largest computed streamer Cd."""


class OpenRocketError(ConfigError):
    """A .ork file that cannot be read or flown; the message is one line naming the file and the component."""


@dataclasses.dataclass(frozen=True)
class ImportedFins:
    """A fin set as rocketmc flies it (``shape``: trapezoidal, root leading edge from the nose tip), with its
    OpenRocket name and how it was converted (``note``; empty for trapezoidal fins)."""

    name: str
    shape: FinSet
    note: str = ""


@dataclasses.dataclass(frozen=True)
class Recovery:
    """A parachute or streamer: drag coefficient on ``area_m2``, where it hangs [m], its deployment event
    (``apogee``, ``altitude``, ``ejection``, ...), altitude [m] and delay [s]."""

    name: str
    kind: str
    cd: float
    area_m2: float
    attach_m: float
    event: str
    altitude_m: float
    delay_s: float


@dataclasses.dataclass(frozen=True)
class MotorMount:
    """The motor mount and the motor the chosen configuration puts in it: its front end and nozzle [m], diameter and
    length [m], the ejection delay [s] (None: plugged)."""

    name: str
    designation: str
    manufacturer: str
    top_m: float
    nozzle_m: float
    diameter_m: float
    length_m: float
    delay_s: float | None


@dataclasses.dataclass
class Design:
    """A rocket read from OpenRocket: positions from the nose tip [m], growing aft."""

    name: str
    version: str
    nose_name: str
    nose_kind: str
    nose_length_m: float
    body_diameter_m: float
    body_names: list[str]
    length_m: float
    boat_tail: tuple[str, float, float, float] | None  # (name, length, aft diameter, front end) [m]
    transitions: list[tuple[str, Transition]]  # (name, shape) of each other change of the body's diameter
    surface_roughness_m: float  # the body's, from its largest component's finish [m]
    fins: list[ImportedFins]
    lugs: list[tuple[str, float]]  # (name, aft end) of each lug or rail button instance
    lug_shapes: list[tuple[str, LaunchLug | RailButton]]  # (name, shape) of each lug and rail button instance
    recovery: list[Recovery]
    mounts: list[tuple[str, ElementTree.Element, float, float]]  # (name, <motormount>, front end, length)
    dry: MassProperties
    parts: int
    warnings: list[str]
    simulations: list[ElementTree.Element]

    def motor_mount(self, config_id: str) -> MotorMount | None:
        """The mount holding a motor in configuration ``config_id`` (None: none); more than one is refused."""
        found = []
        for name, element, top_m, length_m in self.mounts:
            for motor in element.findall("motor"):
                if motor.get("configid") == config_id:
                    found.append((name, motor, element, top_m, length_m))
        if len(found) > 1:
            raise OpenRocketError(f"motor mounts {found[0][0]!r} and {found[1][0]!r} both hold a motor: rocketmc "
                                  "flies one motor")  # fmt: skip
        if not found:
            return None
        name, motor, element, top_m, length_m = found[0]
        motor_length = _number(motor, "length", name)
        nozzle_m = top_m + length_m + _number(element, "overhang", name, 0.0)
        delay = (motor.findtext("delay") or "").strip()
        return MotorMount(name, motor.findtext("designation") or "?", motor.findtext("manufacturer") or "",
                          nozzle_m - motor_length, nozzle_m, _number(motor, "diameter", name), motor_length,
                          float(delay) if _is_number(delay) else None)  # fmt: skip


def read_design(path: str | Path) -> Design:
    """The design in ``path`` (a .ork zip or its bare ``rocket.ork`` XML); an ``OpenRocketError`` naming the
    file for one that cannot be read or flown."""
    path = Path(path)
    root = _document(path)
    try:
        return _Reader(root).design()
    except OpenRocketError as e:
        raise OpenRocketError(f"{path}: {e}") from None


def _document(path: Path) -> ElementTree.Element:
    """The ``<openrocket>`` element of ``path``, its version checked."""
    try:
        data = path.read_bytes()
    except OSError as e:
        raise OpenRocketError(f"{path}: cannot be read ({e.strerror or e})") from None
    if data[:2] == b"PK":
        try:
            with zipfile.ZipFile(path) as archive:
                names = [n for n in archive.namelist() if n.lower().endswith(".ork")]
                if not names:
                    raise OpenRocketError(f"{path}: a zip without rocket.ork, not an OpenRocket design")
                data = archive.read("rocket.ork" if "rocket.ork" in names else names[0])
        except (zipfile.BadZipFile, zipfile.LargeZipFile, EOFError, OSError) as e:
            raise OpenRocketError(f"{path}: a corrupt zip ({e})") from None
    try:
        root = ElementTree.fromstring(data)
    except ElementTree.ParseError as e:
        raise OpenRocketError(f"{path}: malformed XML ({e})") from None
    if root.tag != "openrocket" or root.find("rocket") is None:
        raise OpenRocketError(f"{path}: not an OpenRocket design (no <openrocket> with a <rocket>)")
    version = root.get("version", "")
    if version not in SUPPORTED_VERSIONS:
        raise OpenRocketError(f"{path}: OpenRocket file version {version!r} is not supported "
                              f"({SUPPORTED_VERSIONS[0]} to {SUPPORTED_VERSIONS[-1]})")  # fmt: skip
    return root


def _is_number(text: str) -> bool:
    try:
        return math.isfinite(float(text))
    except ValueError:
        return False


def _number(element: ElementTree.Element, tag: str, name: str, default: float | None = None) -> float:
    """The number in ``<tag>`` ("auto 0.0125" gives 0.0125); ``default`` when it is missing or a bare "auto"."""
    text = (element.findtext(tag) or "").replace("auto", "").strip()
    if text:
        if _is_number(text):
            return float(text)
        raise OpenRocketError(f"component {name!r}: <{tag}> {text[:40]!r} is not a number")
    if default is None:
        raise OpenRocketError(f"component {name!r}: no <{tag}>")
    return default


def _auto(element: ElementTree.Element, tag: str) -> bool:
    """Whether ``<tag>`` says "auto" without a value (OpenRocket computes it from the neighbours)."""
    return (element.findtext(tag) or "").strip() == "auto"


def _placement(element: ElementTree.Element) -> tuple[str, float]:
    """(method, offset [m]) of a component's axial position; ``after`` with 0 when it has none."""
    for tag, key in (("axialoffset", "method"), ("position", "type")):
        found = element.find(tag)
        if found is not None and _is_number((found.text or "").strip()):
            return found.get(key, "after"), float(found.text)
    return "after", 0.0


def _material_density(element: ElementTree.Element, tag: str = "material") -> float:
    """The density of ``<tag density=...>`` [kg/m³, kg/m² or kg/m by the material's type]; 0 if none."""
    found = element.find(tag)
    return float(found.get("density", "0")) if found is not None else 0.0


def _flag(element: ElementTree.Element, tag: str) -> bool:
    return (element.findtext(tag) or "").strip().lower() == "true"


class _Reader:
    """Walks the component tree once, placing each component and adding up its mass."""

    def __init__(self, root: ElementTree.Element):
        self.root = root
        self.rocket = root.find("rocket")
        self.body: list[tuple[str, str, ElementTree.Element, float, float]] = []  # kind, name, element, top, length
        self.fins: list[ImportedFins] = []
        self.lugs: list[tuple[str, float]] = []
        self.lug_shapes: list[tuple[str, LaunchLug | RailButton]] = []
        self.recovery: list[Recovery] = []
        self.mounts: list[tuple[str, ElementTree.Element, float, float]] = []
        self.warnings: list[str] = []
        self.parts = 0
        self.radii: dict[int, tuple[float, float]] = {}

    def design(self) -> Design:
        stages = [s for s in self._children(self.rocket)]
        for stage in stages:
            if stage.tag != "stage":
                self._refuse(stage, f"a {stage.tag} directly in the rocket, not in a stage")
        if not stages:
            raise OpenRocketError("the rocket has no stage")
        for stage in stages[1:]:
            if self._children(stage):
                self._refuse(stage, "a second stage with components (rocketmc flies one stage)")
        self._resolve_radii([c for c in self._children(stages[0]) if c.tag in BODY_KINDS])
        dry = self._component(stages[0], 0.0, 0.0, 0.0, None, [])[0]
        if dry is None or dry.mass <= 0:
            raise OpenRocketError("the rocket has no mass")
        profile = self._profile()
        return Design(name=(self.rocket.findtext("name") or "rocket").strip(), version=self.root.get("version"),
                      **profile, fins=self.fins, lugs=self.lugs, lug_shapes=self.lug_shapes, recovery=self.recovery, mounts=self.mounts, dry=dry,
                      parts=self.parts, warnings=self.warnings,
                      simulations=self.root.findall("simulations/simulation"))  # fmt: skip

    @staticmethod
    def _children(element: ElementTree.Element) -> list[ElementTree.Element]:
        found = element.find("subcomponents")
        return list(found) if found is not None else []

    @staticmethod
    def _name(element: ElementTree.Element) -> str:
        return " ".join((element.findtext("name") or element.tag).split())

    def _refuse(self, element: ElementTree.Element, why: str):
        raise OpenRocketError(f"component {self._name(element)!r} ({element.tag}): {why}")

    def _length(self, element: ElementTree.Element) -> float:
        """The length OpenRocket positions ``element`` by [m]."""
        name, tag = self._name(element), element.tag
        if tag in ASSEMBLIES or tag == "railbutton":
            return 0.0
        if tag in MASS_OBJECTS:
            return _number(element, "packedlength", name)
        if tag in ("trapezoidfinset", "ellipticalfinset"):
            return _number(element, "rootchord", name)
        if tag == "freeformfinset":
            return float(self._fin_points(element)[:, 0].max())
        return _number(element, "length", name)

    def _component(self, element, parent_top_m, parent_length_m, previous_end_m, parent, siblings):
        """(mass properties with the subcomponents', aft end [m]) of ``element``, placed against its parent (the
        element ``parent``, at ``parent_top_m``, ``parent_length_m`` long) and its previous sibling's end."""
        if element.tag in REFUSED:
            self._refuse(element, REFUSED[element.tag])
        length = self._length(element)
        top = self._top(element, parent_top_m, parent_length_m, previous_end_m)
        own = self._own_mass(element, top, length, parent, parent_top_m, siblings)
        children, end = [], top
        kids = self._children(element)
        for kid in kids:
            mass, kid_end = self._component(kid, top, length, end, element, kids)
            if kid.tag in BODY_KINDS:
                end = kid_end
            children.append(mass)
        total = self._overridden(element, own, om.combined(children), top)
        return total, end if element.tag in ASSEMBLIES else top + length

    def _top(self, element, parent_top_m, parent_length_m, previous_end_m) -> float:
        """The front end of ``element`` [m from the nose tip]: body components and stages follow the previous one."""
        length = self._length(element)
        method, offset = _placement(element)
        if element.tag in BODY_KINDS or element.tag in ASSEMBLIES:
            method, offset = "after", offset if method == "after" else 0.0
        top = {"after": previous_end_m + offset, "top": parent_top_m + offset, "absolute": offset,
               "middle": parent_top_m + offset + (parent_length_m - length) / 2,
               "bottom": parent_top_m + offset + parent_length_m - length}.get(method)  # fmt: skip
        if top is None:
            self._refuse(element, f"unknown position method {method!r}")
        return top

    def _overridden(self, element, own: MassProperties | None, children: MassProperties | None, top_m: float):
        """Own and subcomponents' mass with the component's overrides, as OpenRocket applies them: a mass override
        replaces the component's own mass at its CG (an assembly's: at its subcomponents' CG), and theirs too when
        ``overridesubcomponentsmass``; a CG override moves the component's CG (and its subcomponents' when
        ``overridesubcomponentscg``) to ``overridecg`` behind its front end. Radii of gyration are kept."""
        legacy = _flag(element, "overridesubcomponents")
        name = self._name(element)
        if element.find("overridemass") is not None:
            mass = _number(element, "overridemass", name)
            if _flag(element, "overridesubcomponentsmass") or legacy:
                whole = om.combined([own, children])
                at = own if own is not None and element.tag not in ASSEMBLIES else whole
                own = om.scaled(whole, mass)._replace(cg_x=at.cg_x) if whole else om.point(mass, top_m)
                children = None
            elif own is not None:
                own = om.scaled(own, mass)
            else:
                own = om.point(mass, children.cg_x if children else top_m)
        if element.find("overridecg") is not None:
            cg_x = top_m + _number(element, "overridecg", name)
            if own is not None:
                own = own._replace(cg_x=cg_x)
            if children is not None and (_flag(element, "overridesubcomponentscg") or legacy):
                children = children._replace(cg_x=cg_x)
        return om.combined([own, children])

    def _own_mass(self, element, top_m, length_m, parent, parent_top_m, siblings) -> MassProperties | None:
        """The component's own mass properties, CG from the nose tip [m]; registers what the campaign needs."""
        tag, name = element.tag, self._name(element)
        if tag in ASSEMBLIES:
            return None
        self.parts += 1
        if element.find("overridecd") is not None and tag != "transition":
            self.warnings.append(f"component {name!r}: its drag override (Cd {element.findtext('overridecd')}) is not "
                                 "flown: rocketmc computes the drag of every component from its shape")  # fmt: skip
        if element.find("motormount") is not None:
            self.mounts.append((name, element.find("motormount"), top_m, length_m))
        if tag in BODY_KINDS:
            self.body.append((tag, name, element, top_m, length_m))
            part = self._body_mass(element, length_m)
        elif tag in RINGS:
            part = self._ring_mass(element, top_m, length_m, parent, parent_top_m, siblings)
        elif tag in FIN_SETS:
            part = self._fin_set(element, top_m, parent)
        elif tag in MASS_OBJECTS:
            part = self._mass_object(element, top_m, length_m, parent)
        elif tag == "railbutton":
            return self._rail_button(element, top_m)
        else:
            self._refuse(element, "a kind of component this importer does not know")
        return om.moved(part, top_m) if part is not None else None

    def _body_mass(self, element, length_m) -> MassProperties:
        name, density = self._name(element), _material_density(element)
        filled = (element.findtext("thickness") or "").strip() == "filled" or _flag(element, "filled")
        thickness = 0.0 if filled else _number(element, "thickness", name)
        if element.tag == "bodytube":
            radius = self._body_radius(element)
            return om.tube(radius, 0.0 if filled else max(radius - thickness, 0.0), length_m, density)
        fore, aft = self._end_radii(element)
        if element.tag == "nosecone":
            kind = self._nose_kind(element)
            shell = om.shell_of_revolution(lambda x: nose_radius_m(kind, length_m, aft, x), length_m, thickness,
                                           density, filled)  # fmt: skip
        else:
            shell = om.shell_of_revolution(lambda x: fore + (aft - fore) * x / length_m, length_m, thickness,
                                           density, filled)  # fmt: skip
        parts = [shell]
        for end, at in (("fore", -1.0), ("aft", 1.0)):
            shoulder = _number(element, f"{end}shoulderlength", name, 0.0)
            if shoulder <= 0:
                continue
            radius = _number(element, f"{end}shoulderradius", name)
            wall = _number(element, f"{end}shoulderthickness", name, 0.0)
            x0 = length_m if at > 0 else -shoulder
            parts.append(om.moved(om.tube(radius, max(radius - wall, 0.0), shoulder, density), x0))
            if _flag(element, f"{end}shouldercapped"):
                cap_x = length_m + shoulder - wall if at > 0 else -shoulder
                parts.append(om.moved(om.tube(max(radius - wall, 0.0), 0.0, wall, density), cap_x))
        return om.combined(parts)

    def _body_radius(self, element) -> float:
        """A body tube's outer radius [m]."""
        return self._end_radii(element)[1]

    def _end_radii(self, element) -> tuple[float, float]:
        """(fore, aft) outer radii [m] of a body component, its automatic ones resolved (``_resolve_radii``)."""
        return self.radii[id(element)]

    def _resolve_radii(self, body: list[ElementTree.Element]) -> None:
        """The (fore, aft) radii [m] of the body components in ``body``, in order, OpenRocket's automatic ones
        resolved as it does: an automatic body tube takes the aft radius of the component before it (through other
        automatic tubes) unless that one is automatic too, else the fore radius of the one after it; a nose cone's
        or transition's automatic aft radius is the next component's fore radius, its fore radius the previous
        one's aft radius. The number a file writes after "auto" is the last resort."""

        def explicit(i: int, tag: str) -> float | None:
            element = body[i]
            if element.tag == "nosecone" and tag == "foreradius":
                return 0.0
            tag = "radius" if element.tag == "bodytube" else tag
            return None if (element.findtext(tag) or "auto").strip().startswith("auto") else \
                _number(element, tag, self._name(element))  # fmt: skip

        def offered_aft(i: int) -> float | None:  # what component i offers the one after it
            if i < 0:
                return None
            if body[i].tag == "bodytube" and explicit(i, "radius") is None:
                return offered_aft(i - 1)
            return explicit(i, "aftradius")

        def offered_fore(i: int) -> float | None:  # what component i offers the one before it
            if i >= len(body):
                return None
            if body[i].tag == "bodytube" and explicit(i, "radius") is None:
                return offered_fore(i + 1)
            return explicit(i, "foreradius")

        def written(i: int, tag: str) -> float:
            tag = "radius" if body[i].tag == "bodytube" else tag
            value = _number(body[i], tag, self._name(body[i]), math.nan)
            if math.isnan(value):
                self._refuse(body[i], "an automatic radius this importer cannot resolve: give it a value in OpenRocket")
            return value

        for i, element in enumerate(body):
            fore, aft = explicit(i, "foreradius"), explicit(i, "aftradius")
            if fore is None:
                fore = offered_aft(i - 1) if element.tag != "bodytube" or offered_aft(i - 1) is not None \
                    else offered_fore(i + 1)  # fmt: skip
            if aft is None:
                aft = fore if element.tag == "bodytube" else offered_fore(i + 1)
            fore = written(i, "foreradius") if fore is None else fore
            aft = written(i, "aftradius") if aft is None else aft
            self.radii[id(element)] = (fore, aft)

    def _nose_kind(self, element) -> str:
        shape = (element.findtext("shape") or "").strip()
        parameter = _number(element, "shapeparameter", self._name(element), 0.0)
        for (candidate, value), kind in NOSE_SHAPES.items():
            if candidate == shape and (value is None or abs(parameter - value) < SHAPE_PARAMETER_TOLERANCE):
                return kind
        self._refuse(element, f"a {shape} nose of shape parameter {parameter:g}, which rocketmc's nose kinds "
                              "(tangent ogive, conical, elliptical, full parabola, von Kármán, Haack LV) do not "
                              "include")  # fmt: skip

    def _inner_radius(self, element) -> float:
        """The inner radius [m] a component inside ``element`` fits in (its automatic outer radius)."""
        if element is None:
            return 0.0
        name, tag = self._name(element), element.tag
        if tag in BODY_KINDS:
            outer = self._end_radii(element)[1]
            filled = (element.findtext("thickness") or "").strip() == "filled"
            return 0.0 if filled else max(outer - _number(element, "thickness", name), 0.0)
        if tag in RINGS:
            return self._ring_radii(element, None, 0.0, [], 0.0)[1]
        return 0.0

    def _ring_radii(self, element, parent, parent_top_m, siblings, top_m) -> tuple[float, float]:
        """(outer, inner) radii [m] of a tube or ring, OpenRocket's automatic ones resolved: the outer one fits its
        parent; a centering ring's inner one fits the largest inner tube beside it that it overlaps."""
        name, tag = self._name(element), element.tag
        if tag == "launchlug":
            outer = _number(element, "radius", name)
            return outer, max(outer - _number(element, "thickness", name), 0.0)
        outer = self._inner_radius(parent) if _auto(element, "outerradius") else _number(element, "outerradius", name)
        if tag in ("innertube", "tubecoupler", "engineblock"):
            return outer, max(outer - _number(element, "thickness", name), 0.0)
        if tag == "bulkhead":
            return outer, 0.0
        if not _auto(element, "innerradius"):
            return outer, _number(element, "innerradius", name, 0.0)
        inner, length = 0.0, self._length(element)
        parent_length = self._length(parent) if parent is not None else 0.0
        for sibling in siblings:
            if sibling.tag == "innertube":
                s_top = self._top(sibling, parent_top_m, parent_length, parent_top_m)
                if s_top <= top_m + length and top_m <= s_top + self._length(sibling):
                    inner = max(inner, _number(sibling, "outerradius", self._name(sibling)))
        return outer, min(inner, outer)

    def _ring_mass(self, element, top_m, length_m, parent, parent_top_m, siblings) -> MassProperties:
        name, tag = self._name(element), element.tag
        outer, inner = self._ring_radii(element, parent, parent_top_m, siblings, top_m)
        if tag == "innertube":
            cluster = (element.findtext("clusterconfiguration") or "single").strip()
            if cluster != "single":
                self._refuse(element, f"a motor cluster ({cluster}): rocketmc flies one motor on the axis")
        ring = om.tube(outer, inner, length_m, _material_density(element))
        instances = self._instances(element)
        if tag == "launchlug":
            self.lugs.extend((name, top_m + x + length_m) for x in instances)
            self.lug_shapes.extend((name, LaunchLug(top_m + x, length_m, 2 * outer, 2 * inner)) for x in instances)
        return om.combined([om.moved(ring, x) for x in instances])

    def _instances(self, element) -> list[float]:
        """The axial offsets [m] of a component's instances (``instancecount`` spaced ``instanceseparation``)."""
        count = int(_number(element, "instancecount", self._name(element), 1.0))
        separation = _number(element, "instanceseparation", self._name(element), 0.0)
        return [i * separation for i in range(max(count, 1))]

    def _rail_button(self, element, top_m) -> MassProperties:
        """Rail buttons: points on the body (OpenRocket gives them no length), each instance's mass from its
        flange, standoff, base and screw volumes."""
        name = self._name(element)
        outer = _number(element, "outerdiameter", name, 0.0) / 2
        inner = _number(element, "innerdiameter", name, 0.0) / 2
        height = _number(element, "height", name, 0.0)
        base, flange = _number(element, "baseheight", name, 0.0), _number(element, "flangeheight", name, 0.0)
        screw = _number(element, "screwheight", name, 0.0)
        volume = math.pi * (outer**2 * (flange + base + 2 * screw / 3) + inner**2 * max(height - base - flange, 0.0))
        instances = self._instances(element)
        self.lugs.extend((name, top_m + x) for x in instances)
        waist = max(height - base - flange, 0.0)
        self.lug_shapes.extend((name, RailButton(top_m + x, height, 2 * outer, 2 * inner, waist)) for x in instances)
        each = volume * _material_density(element)
        return om.combined([om.point(each, top_m + x) for x in instances])

    def _mass_object(self, element, top_m, length_m, parent) -> MassProperties:
        name, tag = self._name(element), element.tag
        radius = self._inner_radius(parent) if _auto(element, "packedradius") else _number(element, "packedradius", name)
        if tag == "masscomponent":
            mass = _number(element, "mass", name)
        elif tag == "shockcord":
            mass = _number(element, "cordlength", name) * _material_density(element)
        elif tag == "parachute":
            diameter = _number(element, "diameter", name)
            area = math.pi * diameter**2 / 4
            lines = _number(element, "linecount", name, 0.0) * _number(element, "linelength", name, 0.0)
            mass = area * _material_density(element) + lines * _material_density(element, "linematerial")
            self._recovery(element, top_m + length_m / 2, area, _number(element, "cd", name, PARACHUTE_CD))
        else:  # streamer
            strip, width = _number(element, "striplength", name), _number(element, "stripwidth", name)
            density = _material_density(element)
            mass = strip * width * density
            auto_cd = min(0.034 * ((density + 0.025) / 0.105) * (strip + 1) / strip, STREAMER_MAX_CD)
            self._recovery(element, top_m + length_m / 2, strip * width, _number(element, "cd", name, auto_cd))
        return om.solid_cylinder(mass, radius, length_m)

    def _recovery(self, element, attach_m, area_m2, cd):
        name = self._name(element)
        self.recovery.append(Recovery(name, element.tag, cd, area_m2, attach_m,
                                      (element.findtext("deployevent") or "apogee").strip(),
                                      _number(element, "deployaltitude", name, 0.0),
                                      _number(element, "deploydelay", name, 0.0)))  # fmt: skip

    def _fin_points(self, element) -> np.ndarray:
        points = [(float(p.get("x", "nan")), float(p.get("y", "nan"))) for p in element.iter("point")]
        array = np.array(points, dtype=float).reshape(-1, 2)
        if len(array) < 3 or not np.all(np.isfinite(array)):
            self._refuse(element, "a free-form fin without three finite points")
        return array

    def _fin_set(self, element, top_m, parent) -> MassProperties:
        name, tag = self._name(element), element.tag
        if parent is None or parent.tag != "bodytube":
            self._refuse(element, "fins on a component other than a body tube")
        count = int(_number(element, "fincount", name, _number(element, "instancecount", name, 1.0)))
        thickness = _number(element, "thickness", name)
        cant = _number(element, "cant", name, 0.0)
        if tag == "trapezoidfinset":
            root, tip = _number(element, "rootchord", name), _number(element, "tipchord", name)
            span, sweep = _number(element, "height", name), _number(element, "sweeplength", name)
            points = om.trapezoid_points(root, tip, span, sweep)
            shape = om.Trapezoid(root, tip, span, sweep, True)
            note = ""
        else:
            points = (om.ellipse_points(_number(element, "rootchord", name), _number(element, "height", name))
                      if tag == "ellipticalfinset" else self._fin_points(element))  # fmt: skip
            shape = om.equivalent_trapezoid(points)
            what = "elliptical" if tag == "ellipticalfinset" else "free-form"
            kept = "planform area and axial area centroid" if shape.area_kept else "axial area centroid (not its " \
                "area: it is smaller than the triangle on its root chord and span)"  # fmt: skip
            note = (f"{what} fins flown as the trapezoid of the same span, root chord and {kept}; rocketmc's fins "
                    "are trapezoidal")  # fmt: skip
            self.warnings.append(f"fin set {name!r}: {note}")
        profile = (element.findtext("crosssection") or "square").strip()
        self.fins.append(ImportedFins(name, FinSet(count, shape.root_chord_m, shape.tip_chord_m, shape.span_m,
                                                   shape.sweep_m, top_m, thickness, cant,
                                                   profile=profile if profile in CROSS_SECTIONS else "square",
                                                   surface_roughness_m=self._roughness(element)), note))  # fmt: skip
        body_radius = self._body_radius(parent)
        factor = CROSS_SECTIONS.get((element.findtext("crosssection") or "square").strip(), 1.0)
        density = _material_density(element)
        parts = [om.fin_set(om.planform(points), count, thickness, density, body_radius, factor)]
        tab_height, tab_length = _number(element, "tabheight", name, 0.0), _number(element, "tablength", name, 0.0)
        if tab_height > 0 and tab_length > 0:
            parts.append(self._tab(element, points, tab_height, tab_length, count, thickness, density, body_radius))
        if _number(element, "filletradius", name, 0.0) > 0:
            self.warnings.append(f"fin set {name!r}: its fillets' mass is left out")
        return om.combined(parts)

    def _tab(self, element, points, height_m, length_m, count, thickness_m, density, body_radius_m):
        """A fin tab: a rectangle inside the body, ``height_m`` deep, placed as OpenRocket's ``tabposition``
        says (relative to the root chord's front, centre or end)."""
        root = float(points[:, 0].max())
        found = element.find("tabposition")
        offset = float(found.text) if found is not None and _is_number(found.text or "") else 0.0
        relative = found.get("relativeto", "center") if found is not None else "center"
        centre = {"front": offset + length_m / 2, "top": offset + length_m / 2, "end": root + offset - length_m / 2,
                  "bottom": root + offset - length_m / 2}.get(relative, root / 2 + offset)  # fmt: skip
        rectangle = np.array([[centre - length_m / 2, 0.0], [centre + length_m / 2, 0.0],
                              [centre + length_m / 2, -height_m], [centre - length_m / 2, -height_m]])  # fmt: skip
        return om.fin_set(om.planform(rectangle), count, thickness_m, density, body_radius_m)

    def _roughness(self, element) -> float:
        """The roughness height [m] of ``element``'s ``<finish>`` (OpenRocket's default: regular paint)."""
        finish = (element.findtext("finish") or "normal").strip()
        if finish not in OPENROCKET_FINISHES_M:
            self._refuse(element, f"an unknown surface finish {finish!r}")
        return OPENROCKET_FINISHES_M[finish]

    def _profile(self) -> dict:
        """The body as rocketmc describes it: the nose, its base diameter, the aft narrowing transition as the
        boat-tail, every other change of diameter (transitions, tubes of another diameter) as a conical section
        (a transition whose drag OpenRocket overrides keeps the override); the body's roughness that of its largest
        surface."""
        if not self.body or self.body[0][0] != "nosecone":
            raise OpenRocketError("the rocket does not start with a nose cone")
        nose_kind, nose_name, nose_element, nose_top, nose_length = self.body[0]
        if _flag(nose_element, "isflipped"):
            self._refuse(nose_element, "a flipped nose cone (a tail cone)")
        radius = body_radius = self._end_radii(nose_element)[1]
        boat_tail, transitions, names = None, [], []
        for i, (kind, name, element, top, length) in enumerate(self.body[1:], start=1):
            fore, aft = self._end_radii(element)
            same = abs(fore - radius) < RADIUS_TOLERANCE_M
            if kind == "transition" and (element.findtext("shape") or "conical").strip() != "conical":
                self.warnings.append(f"transition {name!r}: a {element.findtext('shape')} transition flown as a "
                                     "conical one of the same length and diameters")  # fmt: skip
            overridden = kind == "transition" and element.find("overridecd") is not None
            override = _number(element, "overridecd", name) if overridden else None
            if kind == "transition" and i == len(self.body) - 1 and same and aft < fore and radius == body_radius \
                    and override is None:  # fmt: skip
                boat_tail = (name, length, 2 * aft, top)
            elif kind == "transition" or not same:
                fore = radius if same else fore
                transitions.append((name, Transition(top, length, 2 * fore, 2 * aft, override)))
            elif abs(radius - body_radius) < RADIUS_TOLERANCE_M:
                names.append(name)
            radius = aft if kind == "transition" or not same else radius
        areas = [(length * (sum(self._end_radii(e)) + 1e-12), e) for kind, _, e, _, length in self.body
                 if not (kind == "transition" and e.find("overridecd") is not None)]  # its friction is in its override
        finishes = {(e.findtext("finish") or "normal").strip() for _, e in areas}
        largest = max(areas, key=lambda item: item[0])[1]
        if len(finishes) > 1:
            self.warnings.append(f"the body's components have the finishes {', '.join(sorted(finishes))}: the body "
                                 f"flies the roughness of its largest, {self._name(largest)!r}")  # fmt: skip
        end = self.body[-1][3] + self.body[-1][4]
        return dict(nose_name=nose_name, nose_kind=self._nose_kind(nose_element), nose_length_m=nose_length,
                    body_diameter_m=2 * body_radius, body_names=names, length_m=end - nose_top, boat_tail=boat_tail,
                    transitions=transitions, surface_roughness_m=self._roughness(largest))  # fmt: skip


@dataclasses.dataclass(frozen=True)
class Simulation:
    """One of the design's simulations: its 1-based ``index``, name, motor configuration, conditions (tag → text),
    atmosphere element and, when it was run and saved, its flight data: the ``summary`` (``<flightdata>``'s
    attributes: maxaltitude, maxvelocity, timetoapogee, launchrodvelocity, ... in SI), the first branch's columns
    by name (``Time``, ``Thrust``, ``Mass``, ``CG location``, ...) and its events (type → times [s])."""

    index: int
    name: str
    config_id: str
    conditions: dict[str, str]
    atmosphere: ElementTree.Element | None
    wind_levels: list[dict[str, str]]
    summary: dict[str, float]
    columns: dict[str, np.ndarray]
    events: dict[str, list[float]]

    @property
    def label(self) -> str:
        """How the campaign cites it: "stored simulation 1 ('Name')"."""
        return f"stored simulation {self.index} ({self.name!r})"

    def at_liftoff(self, column: str) -> float | None:
        """The stored ``column`` at t = 0 (None without flight data or that column)."""
        values = self.columns.get(column)
        return float(values[0]) if values is not None and len(values) else None

    def condition(self, tag: str, default: float) -> float:
        text = self.conditions.get(tag, "")
        return float(text) if _is_number(text) else default


def read_simulation(design: Design, index: int | None) -> Simulation | None:
    """Simulation ``index`` (1-based; None: the first, or None if the design has none) of ``design``; an
    ``OpenRocketError`` for an index it does not have."""
    if index is None and not design.simulations:
        return None
    index = 1 if index is None else index
    if not 1 <= index <= len(design.simulations):
        raise OpenRocketError(f"--simulation {index}: the design has {len(design.simulations)} simulation(s)")
    element = design.simulations[index - 1]
    conditions = element.find("conditions")
    conditions = conditions if conditions is not None else ElementTree.Element("conditions")
    flight = element.find("flightdata")
    branch = flight.find("databranch") if flight is not None else None
    summary, columns, events = {}, {}, {}
    if branch is not None:
        summary = {k: float(v) for k, v in flight.attrib.items() if _is_number(v)}
        types = branch.get("types", "").split(",")
        rows = [[float(v) if _is_number(v) else math.nan for v in (p.text or "").split(",")]
                for p in branch.iter("datapoint")]  # fmt: skip
        rows = [row for row in rows if len(row) == len(types)]
        table = np.array(rows, dtype=float).reshape(-1, len(types))
        columns = {name: table[:, i] for i, name in enumerate(types)}
        for event in branch.iter("event"):
            if _is_number(event.get("time", "")):
                events.setdefault(event.get("type", ""), []).append(float(event.get("time")))
    return Simulation(index, " ".join((element.findtext("name") or f"Simulation {index}").split()),
                      (conditions.findtext("configid") or "").strip(),
                      {c.tag: (c.text or "").strip() for c in conditions}, conditions.find("atmosphere"),
                      [{**level.attrib, "altituderef": wind.get("altituderef", "msl")}
                       for wind in conditions.iter("wind") for level in wind.iter("windlevel")],
                      summary, columns, events)  # fmt: skip


def stored_dry_mass(simulation: Simulation, mount: MotorMount) -> MassProperties | None:
    """The rocket without its motor as ``simulation`` stored it at t = 0: the stored Mass, CG location and moments
    of inertia less the motor (the stored Motor mass, a solid cylinder of the motor's diameter and length centred
    in it, as OpenRocket models a motor); None without those columns. The stored values are rounded (three
    decimals, or four significant digits below 0.01)."""
    mass, cg_x, motor = (simulation.at_liftoff(c) for c in ("Mass", "CG location", "Motor mass"))
    if mass is None or cg_x is None or motor is None:
        return None
    motor_x = mount.top_m + mount.length_m / 2
    case = om.moved(om.solid_cylinder(motor, mount.diameter_m / 2, mount.length_m), mount.top_m)
    dry_mass = mass - motor
    dry_cg = (mass * cg_x - motor * motor_x) / dry_mass
    ixx, iyy = simulation.at_liftoff("Rotational moment of inertia"), simulation.at_liftoff("Longitudinal moment of inertia")
    if ixx is None or iyy is None:
        return MassProperties(dry_mass, dry_cg, math.nan, math.nan)
    iyy_dry = iyy - case.iyy - motor * (motor_x - cg_x) ** 2 - dry_mass * (dry_cg - cg_x) ** 2
    return MassProperties(dry_mass, dry_cg, ixx - case.ixx, iyy_dry)

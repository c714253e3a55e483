"""The reference of every campaign key (type, unit, default, range, meaning, whether dispersible), generated
from the schema (``campaign/schema.py``) so that it cannot drift from it. Regenerate the committed page with

    python -m rocketmc.campaign.reference > docs/campaign_reference.md

(tests/campaign/test_reference.py fails until the page equals this module's output)."""

from __future__ import annotations

import inspect
import types
import typing
from collections.abc import Iterator

from annotated_types import Ge, Gt, Le, Lt, MaxLen, MinLen
from pydantic import BaseModel
from pydantic.fields import FieldInfo
from pydantic_core import PydanticUndefined

from .limits import DISPERSIBLE_SECTIONS, fixed_reason
from .schema import CampaignConfig, SensorConfig

UNITS = {
    "_deg_s2": "deg/s²", "_deg_s": "deg/s", "_rad_s": "rad/s", "_n_s_per_m": "N·s/m", "_n_per_m": "N/m", "_per_m_s": "1/(m·s)", "_per_s": "1/s", "_per_kpa": "unit/kPa", "_kgm2": "kg·m²", "_m2": "m²", "_mps2": "m/s²", "_mps": "m/s", "_kpa": "kPa", "_kg": "kg", "_deg": "deg",
    "_hz": "Hz", "_s2": "s²", "_s": "s", "_m": "m", "_pa": "Pa", "_nt": "nT", "_n": "N",
}  # fmt: skip
"""Unit of a key from its name's suffix (the project's convention: the unit ends the name), the first that
matches (so the longer suffixes first); "unit" is the sensor's own (docs/sensors.md)."""
INDEX = "<i>"
"""Stands for a list index in a key's path (dispersions write it as a number: ``rocket.geometry.fins.0.span_m``)."""


def unit(name: str) -> str:
    """The unit a key's name ends with, or "" (dimensionless, or said in its meaning)."""
    return next((u for suffix, u in UNITS.items() if name.endswith(suffix)), "")


def _models(annotation) -> list[type[BaseModel]]:
    """The schema models inside ``annotation`` (a model, ``X | None``, ``list[X]``, ``dict[str, X]``)."""
    if inspect.isclass(annotation) and issubclass(annotation, BaseModel):
        return [annotation]
    return [m for arg in typing.get_args(annotation) for m in _models(arg)]


def _type(annotation) -> str:
    """A short name of a field's type: float, int, str, bool, list of float, one of 'a'/'b', [section]."""
    origin, args = typing.get_origin(annotation), typing.get_args(annotation)
    if origin is typing.Annotated:
        return _type(args[0])
    if origin is typing.Literal:
        return "one of " + ", ".join(f"`{a!r}`" for a in args)
    if origin in (typing.Union, types.UnionType):
        return " or ".join(_type(a) for a in args if a is not type(None))
    if origin is list:
        return f"list of {_type(args[0])}"
    if origin is dict:
        return f"table of {_type(args[1])}"
    if inspect.isclass(annotation) and issubclass(annotation, BaseModel):
        return "table"
    return getattr(annotation, "__name__", str(annotation))


def _bounds(metadata: list) -> str:
    """The range a field's constraints allow: ``≥ 0, ≤ 10``, ``> 0``, ``length ≥ 2``, ..."""
    parts = []
    for m in metadata:
        for kind, attribute, word in ((Ge, "ge", "≥"), (Gt, "gt", ">"), (Le, "le", "≤"), (Lt, "lt", "<")):
            if isinstance(m, kind):
                value = getattr(m, attribute)
                parts.append(f"{word} {value if isinstance(value, int) else f'{value:g}'}")
        if isinstance(m, MinLen):
            parts.append(f"length ≥ {m.min_length}")
        if isinstance(m, MaxLen):
            parts.append(f"length ≤ {m.max_length}")
    return ", ".join(parts)


def _element_bounds(annotation) -> str:
    """The bounds of a list's or an optional number's inner ``Annotated`` type."""
    for arg in typing.get_args(annotation):
        if typing.get_origin(arg) is typing.Annotated:
            return _bounds([m for a in typing.get_args(arg)[1:] for m in getattr(a, "metadata", [a])])
        if inner := _element_bounds(arg):
            return inner
    return ""


def _numeric(annotation) -> bool:
    """Whether a field holds a number or a list of numbers (what a dispersion can draw)."""
    if annotation in (float, int):
        return True
    return typing.get_origin(annotation) is not dict and any(_numeric(a) for a in typing.get_args(annotation)
                                                                if not isinstance(a, FieldInfo))  # fmt: skip


def _default(field: FieldInfo, model: type[BaseModel]) -> str:
    """A field's default as written in TOML; a sensor's required keys come from its part file."""
    if field.is_required():
        return "from the part" if issubclass(model, SensorConfig) else "required"
    value = field.get_default(call_default_factory=True) if field.default is PydanticUndefined else field.default
    if isinstance(value, BaseModel):
        return "its defaults"
    return "none" if value is None else f"`{value!r}`"


def _dispersible(path: str, annotation) -> str:
    if not _numeric(annotation) or not path.startswith(DISPERSIBLE_SECTIONS) or path.startswith("dispersions"):
        return "no"
    if fixed_reason(path.replace(INDEX, "0")) is not None:
        return "no (fixed per campaign)"
    origin = typing.get_origin(annotation)
    listed = origin is list or any(typing.get_origin(a) is list for a in typing.get_args(annotation))
    return "yes, per element (`.0`, `.1`, ...)" if listed else "yes"


def rows(model: type[BaseModel] = CampaignConfig, prefix: str = "") -> Iterator[tuple[str, ...]]:
    """(key, type, unit, default, range, dispersible, meaning) of every key of ``model``, depth first; a
    section's keys follow its own row, a list of tables' with ``<i>``, a table of tables' with ``<path>``."""
    for name, field in model.model_fields.items():
        path = f"{prefix}{name}"
        annotation = field.annotation
        meaning = field.description or ""
        nested = _models(annotation)
        yield (path, _type(annotation), unit(name), _default(field, model),
               ", ".join(b for b in (_element_bounds(annotation), _bounds(field.metadata)) if b),
               _dispersible(path, annotation),
               meaning or inspect.cleandoc(nested[0].__dict__.get("__doc__") or "") if nested else meaning)  # fmt: skip
        for sub in nested:
            origin = typing.get_origin(annotation)
            lists = origin is list or any(typing.get_origin(a) is list for a in typing.get_args(annotation))
            key = f"{path}.{INDEX}." if lists else f"{path}.<path>." if origin is dict else f"{path}."
            yield from rows(sub, key)


def _cell(text: str) -> str:
    return " ".join(text.split()).replace("|", "\\|")


def reference() -> str:
    """The Markdown page of every campaign key."""
    lines = [
        "# Campaign keys",
        "",
        "Every key of a campaign file, generated from the schema (`src/rocketmc/campaign/schema.py`); do not edit by",
        "hand: `python -m rocketmc.campaign.reference > docs/campaign_reference.md` regenerates it. Units follow the",
        "name's suffix (`_m`, `_s`, `_deg`, `_mps`, ...) or are said in the meaning; positions are in the rocket's",
        "coordinates (`rocket.coordinate_system`). `<i>` is a list index, `<path>` a dotted key. Dispersible: a",
        "`[dispersions]` entry may draw it per realization (docs/conventions.md, Campaign validation).",
        "",
        "| key | type | unit | default | range | dispersible | meaning |",
        "|---|---|---|---|---|---|---|",
    ]
    lines += ["| " + " | ".join(_cell(c) if i else f"`{c}`" for i, c in enumerate(row)) + " |" for row in rows()]
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    print(reference(), end="")

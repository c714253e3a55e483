"""The table of the built-in motor library that ``rocketmc motors`` prints."""

from __future__ import annotations

from ..dynamics.motor_library import MotorEntry
from .results import text_table

COLUMNS = ["motor", "designation", "maker", "diameter mm", "length mm", "impulse N·s", "class", "avg thrust N",
           "burn s", "propellant kg", "total kg"]  # fmt: skip
"""The table's columns: the file's name, the header's designation and manufacturer, the casing, the curve's total
impulse, its NAR class, its average thrust over its burn time (thrust ≥ 5 % of the maximum), the masses at
ignition."""


def motor_table(entries: list[MotorEntry]) -> str:
    """``entries`` as an aligned text table under ``COLUMNS``, one line each."""
    rows = [
        [e.name, e.designation, e.manufacturer, f"{e.diameter_m * 1000:g}", f"{e.length_m * 1000:g}",
         f"{e.total_impulse_ns:.0f}", e.impulse_class, f"{e.average_thrust_n:.0f}", f"{e.burn_time_s:.2f}",
         f"{e.propellant_mass_kg:.3f}", f"{e.total_mass_kg:.3f}"]
        for e in entries
    ]  # fmt: skip
    return "\n".join(text_table(COLUMNS, rows, "lll" + "r" * (len(COLUMNS) - 3)))

"""Canard mixing, the airframe's: four deflections δ1..δ4 ↔ virtual commands u = (yaw, pitch, roll, squeeze).

The thesis's matrix (Hixos/RocketControl; ../../docs/conventions.md), rows u, columns δ:

    yaw     = (−δ1 + δ3) / 2
    pitch   = ( δ2 − δ4) / 2
    roll    = −(δ1 + δ2 + δ3 + δ4) / 4
    squeeze = (−δ1 + δ2 − δ3 + δ4) / 4

Written on scalar components (see docs/sharp-bits.md). ``allocate`` is its exact inverse. It lives in
``aero`` because it describes the airframe (the panels' numbering), not the controller: ``gnc``
imports ``aero``, never the reverse.
"""

from __future__ import annotations


def mix(d1, d2, d3, d4):
    """Virtual commands (yaw, pitch, roll, squeeze) [rad] from fin deflections [rad]."""
    return (
        0.5 * (d3 - d1),
        0.5 * (d2 - d4),
        -0.25 * (d1 + d2 + d3 + d4),
        0.25 * (d2 + d4 - d1 - d3),
    )


def allocate(yaw, pitch, roll, squeeze=0.0):
    """Fin deflections (δ1, δ2, δ3, δ4) [rad] that produce the virtual commands; ``mix`` ∘ ``allocate`` = id."""
    return (
        -yaw - roll - squeeze,
        pitch - roll + squeeze,
        yaw - roll - squeeze,
        -pitch - roll + squeeze,
    )

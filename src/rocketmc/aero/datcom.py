"""Missile DATCOM coefficient tables in Skyward's .mat format, loaded as a ``Table``.

The table's axes are (alpha [rad], mach [-], beta [rad], altitude [m]) and its 26 outputs are
``DATCOM_COEFFS`` in that order (derivatives per radian; reference area 0.01767 m^2, reference length
0.15 m for the Lynx table; see data/aero/SOURCE.md).
"""

from __future__ import annotations

from importlib import resources

import numpy as np

from ..math.table import Table

LYNX_DATCOM = resources.files("rocketmc") / "data" / "aero" / "lynx_datcom_full_2021-03-20.mat"

DATCOM_AXES = ("alpha", "mach", "beta", "altitude")
DATCOM_COEFFS = (
    "CN", "CM", "CA", "CY", "CLN", "CLL", "CL", "CD", "CL_CD", "X_C_P",
    "CNA", "CMA", "CYB", "CLNB", "CLLB", "CNQ", "CMQ", "CAQ", "CNAD", "CMAD",
    "CYR", "CLNR", "CLLR", "CYP", "CLNP", "CLLP",
)  # fmt: skip


class DatcomFileError(ValueError):
    """A DATCOM .mat file is missing or lacks a field the table needs."""


def load_datcom_mat(path) -> Table:
    """``Table`` of the 26 DATCOM coefficients from a Skyward .mat (``State`` + ``Coeffs`` structs).

    ``State`` holds Alphas [deg], Machs, Betas [deg], Altitudes [m]; each ``Coeffs`` field is an
    array (alpha, mach, beta, altitude). Raises ``DatcomFileError`` naming the file and what is missing.
    """
    import scipy.io  # here, not at import: ~0.08 s before the first flight of a campaign without DATCOM tables

    try:
        with open(path, "rb") as file:
            mat = scipy.io.loadmat(file, squeeze_me=True, struct_as_record=False)
    except FileNotFoundError:
        raise DatcomFileError(f"{path}: DATCOM file not found") from None
    except Exception as err:  # scipy raises several types on non-.mat bytes
        raise DatcomFileError(f"{path}: not a readable MATLAB .mat file ({err})") from None

    def field(struct_name, name):
        struct = mat.get(struct_name)
        if struct is None:
            raise DatcomFileError(f"{path}: missing struct {struct_name!r}")
        if name not in getattr(struct, "_fieldnames", ()):
            raise DatcomFileError(f"{path}: missing field {struct_name}.{name}")
        return np.asarray(getattr(struct, name), dtype=np.float64)

    alphas, machs, betas, altitudes = (field("State", n) for n in ("Alphas", "Machs", "Betas", "Altitudes"))
    grid = (alphas.size, machs.size, betas.size, altitudes.size)
    coeffs = []
    for name in DATCOM_COEFFS:
        c = field("Coeffs", name)
        if c.shape != grid:
            raise DatcomFileError(f"{path}: Coeffs.{name} has shape {c.shape}, expected (alpha, mach, beta, altitude) {grid}")
        coeffs.append(c)
    try:
        return Table.from_numpy(
            (np.deg2rad(alphas), machs, np.deg2rad(betas), altitudes),
            np.stack(coeffs, axis=-1),
            DATCOM_AXES,
            DATCOM_COEFFS,
        )
    except ValueError as err:
        raise DatcomFileError(f"{path}: bad State grid: {err}") from None

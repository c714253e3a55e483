"""Reading and writing ``AeroTables``: Missile DATCOM .mat import, HDF5 files, long-format CSV.

* HDF5 (``save_aero_tables`` / ``load_aero_tables``) stores everything, bit for bit:
  root attributes ``format = "rocketmc-aero"``, ``format_version``, ``reference_area_m2``,
  ``reference_length_m``, ``moment_reference_m``, ``source``, ``rocketmc_version``; group ``/body``
  with ``axes/<name>`` datasets (attribute ``unit``), ``values`` (*grid, n_outputs) and attributes
  ``axis_names``, ``output_names``; optional group ``/canards``, laid out the same, with attributes
  ``roll_angles_rad``, ``cp_m``, ``cp_radius_m``.
* CSV (``read_aero_csv`` / ``write_aero_csv``), for tables from other tools: see ``read_aero_csv``.
* ``load_aero`` picks the reader from the file's extension.

Every reading error is an ``AeroFileError`` whose one-line message starts with the file's path.
"""

from __future__ import annotations

import math
from pathlib import Path

import h5py
import numpy as np

from ..runtime import __version__
from ..files import replacing
from .datcom import DATCOM_COEFFS, LYNX_DATCOM, DatcomFileError, load_datcom_mat
from .tables import AXIS_UNITS, BODY_COEFFS, AeroTables, CanardPanels, GriddedCoefficients

FORMAT = "rocketmc-aero"
FORMAT_VERSION = 1
REFERENCE_KEYS = ("reference_area_m2", "reference_length_m", "moment_reference_m")

DATCOM_NAMES = dict(zip(BODY_COEFFS, ("CA", "CY", "CN", "CLL", "CM", "CLN", "CNQ", "CMQ", "CYR", "CLNR", "CLLP")))
"""The DATCOM output behind each body coefficient. DATCOM's body axes and signs are ours (CN up,
CY right, Cl right wing down, Cm nose up, Cn nose right; rates per ω·d/(2V)), so none changes sign.
Checked on the Lynx table: CYβ < 0 ≈ −CNα, Cnβ > 0 ≈ −Cmα, CNq, CYr > 0, Cmq, Cnr, Clp < 0, and
X_C_P = CM/CN (to the 3 printed decimals), the centre of pressure in calibers forward of XCG."""
DAMPING_AT_ZERO_SIDESLIP = ("CNq", "Cmq", "CYr", "Cnr")
"""Derivatives that ``datcom_tables`` takes at β = 0 for every β (see there)."""

CSV_AXIS_COLUMNS = {"alpha": "alpha_deg", "beta": "beta_deg", "mach": "mach", "altitude": "altitude_m"}
"""CSV column of each body axis; angles are in degrees there."""
CSV_HEADER_KEYS = REFERENCE_KEYS + ("source",)
CSV_REQUIRED = {"alpha": ("CN", "Cm"), "beta": ("CY", "Cn")}
"""Coefficient columns a CSV file must have with an angle axis, besides CA: those the angle drives."""


class AeroFileError(ValueError):
    """An aerodynamic file is missing, of the wrong kind, or lacks or garbles a field."""


def _existing(path) -> Path:
    path = Path(path)
    if not path.is_file():
        raise AeroFileError(f"{path}: file not found")
    return path


# --- Missile DATCOM ------------------------------------------------------------------------------


def datcom_tables(path, *, reference_area_m2, reference_length_m, moment_reference_m, source=None) -> AeroTables:
    """Body table from a Skyward DATCOM .mat (see ``datcom.load_datcom_mat``).

    Axes (alpha [rad], mach, beta [rad], altitude [m]) as in the file; reference area S [m²],
    length d [m] and moment point [m from the nose tip] are those DATCOM was run with (the .mat does
    not record them).

    The pitch and yaw damping derivatives are taken at β = 0 (the grid's β closest to 0) for every
    β: at any β ≠ 0 DATCOM's CNQ, CMQ, CYR and CLNR drop to 5-30 % of their β = 0 values (Lynx,
    Mach 0.3, α = 0: CMQ −726 at β = 0, −24.8 at β = ±0.1°; CNQ 144 against 14) while CNA and CMA
    change by < 0.1 % over the same step: an artefact of the DATCOM runs, not aerodynamics.
    """
    try:
        table = load_datcom_mat(path)
    except DatcomFileError as err:
        raise AeroFileError(str(err)) from None
    values = np.asarray(table.values)[..., [DATCOM_COEFFS.index(DATCOM_NAMES[n]) for n in BODY_COEFFS]]
    beta = table.axis_names.index("beta")
    zero_sideslip = [int(np.argmin(np.abs(np.asarray(table.axes[beta]))))]
    for name in DAMPING_AT_ZERO_SIDESLIP:
        k = BODY_COEFFS.index(name)
        values[..., k] = np.take(values[..., k], zero_sideslip, axis=beta)
    body = GriddedCoefficients(table.axis_names, tuple(np.asarray(a) for a in table.axes), BODY_COEFFS, values)
    return AeroTables(
        reference_area_m2,
        reference_length_m,
        moment_reference_m,
        body,
        source=source or f"Missile DATCOM table {Path(path).name}",
    )


def lynx_datcom_tables() -> AeroTables:
    """The vendored Lynx DATCOM table (data/aero/SOURCE.md): S 0.01767 m², d 0.15 m, moments about
    XCG = 1.49 m from the nose tip."""
    return datcom_tables(
        LYNX_DATCOM,
        reference_area_m2=0.01767,
        reference_length_m=0.15,
        moment_reference_m=1.49,
        source="Lynx, Missile DATCOM (Skyward msa-toolkit data/full.mat, 2021-03-20), full propellant",
    )


# --- HDF5 ----------------------------------------------------------------------------------------


def _write_table(group: h5py.Group, table: GriddedCoefficients) -> None:
    group.attrs["axis_names"] = np.array(table.axis_names, dtype=h5py.string_dtype())
    group.attrs["output_names"] = np.array(table.output_names, dtype=h5py.string_dtype())
    for name, axis in zip(table.axis_names, table.axes):
        group.create_dataset(f"axes/{name}", data=axis).attrs["unit"] = AXIS_UNITS[name]
    group.create_dataset("values", data=table.values)


def save_aero_tables(path, tables: AeroTables) -> None:
    """Writes ``tables`` to the HDF5 file ``path`` (replaced atomically: written aside, then moved)."""
    with replacing(path) as partial, h5py.File(partial, "w") as file:
        file.attrs["format"] = FORMAT
        file.attrs["format_version"] = FORMAT_VERSION
        for key in REFERENCE_KEYS:
            file.attrs[key] = float(getattr(tables, key))
        file.attrs["source"] = tables.source
        file.attrs["rocketmc_version"] = __version__
        _write_table(file.create_group("body"), tables.body)
        if tables.canards is not None:
            canards = file.create_group("canards")
            _write_table(canards, tables.canards.table)
            canards.attrs["roll_angles_rad"] = np.asarray(tables.canards.roll_angles_rad, dtype=np.float64)
            canards.attrs["cp_m"] = float(tables.canards.cp_m)
            canards.attrs["cp_radius_m"] = float(tables.canards.cp_radius_m)


def _member(group: h5py.Group, name: str, path: Path):
    if name not in group:
        raise AeroFileError(f"{path}: missing {group.name.rstrip('/')}/{name}")
    return group[name]


def _attr(node, name: str, path: Path):
    if name not in node.attrs:
        raise AeroFileError(f"{path}: missing attribute {name!r} of {node.name}")
    return node.attrs[name]


def _read_table(group: h5py.Group, path: Path) -> GriddedCoefficients:
    axis_names = tuple(str(n) for n in _attr(group, "axis_names", path))
    output_names = tuple(str(n) for n in _attr(group, "output_names", path))
    axes = []
    for name in axis_names:
        dataset = _member(_member(group, "axes", path), name, path)
        unit = _attr(dataset, "unit", path)
        if name in AXIS_UNITS and unit != AXIS_UNITS[name]:  # an unknown name is the tables' to refuse
            raise AeroFileError(f"{path}: {dataset.name} has unit {unit!r}, expected {AXIS_UNITS[name]!r}")
        axes.append(dataset[()])
    return GriddedCoefficients(axis_names, tuple(axes), output_names, _member(group, "values", path)[()])


def _read_tables(file: h5py.File, path: Path) -> AeroTables:
    if file.attrs.get("format") != FORMAT:
        raise AeroFileError(f"{path}: not a rocketmc aero file (no format = {FORMAT!r} attribute)")
    version = _attr(file, "format_version", path)
    if version != FORMAT_VERSION:
        raise AeroFileError(
            f"{path}: format_version {version} is not the version this rocketmc reads ({FORMAT_VERSION})"
        )
    canards = None
    if "canards" in file:
        group = file["canards"]
        canards = CanardPanels(
            _read_table(group, path),
            tuple(float(phi) for phi in _attr(group, "roll_angles_rad", path)),
            float(_attr(group, "cp_m", path)),
            float(_attr(group, "cp_radius_m", path)),
        )
    return AeroTables(
        *(float(_attr(file, key, path)) for key in REFERENCE_KEYS),
        body=_read_table(_member(file, "body", path), path),
        canards=canards,
        source=str(_attr(file, "source", path)),
    )


def load_aero_tables(path) -> AeroTables:
    """``AeroTables`` from an HDF5 file written by ``save_aero_tables``, exactly as saved."""
    path = _existing(path)
    try:
        with h5py.File(path, "r") as file:
            return _read_tables(file, path)
    except AeroFileError:
        raise
    except (OSError, RuntimeError, KeyError) as err:  # h5py's errors on damaged files
        raise AeroFileError(f"{path}: not a readable HDF5 file ({err})") from None
    except (ValueError, TypeError) as err:  # the tables' own validation
        raise AeroFileError(f"{path}: {err}") from None


# --- CSV -----------------------------------------------------------------------------------------


def _csv_header(path: Path) -> tuple[dict[str, str], int]:
    """The ``# key = value`` lines at the top of a CSV file and the number of ``#`` lines there."""
    header, n_lines = {}, 0
    with open(path, encoding="utf-8-sig") as file:  # -sig: spreadsheets often start with a BOM
        for line in file:
            if not line.startswith("#"):
                break
            n_lines += 1
            key, equals, value = line[1:].partition("=")
            if equals:
                if key.strip() not in CSV_HEADER_KEYS:
                    raise AeroFileError(
                        f"{path}:{n_lines}: unknown key {key.strip()!r}, expected one of {CSV_HEADER_KEYS}"
                    )
                header[key.strip()] = value.strip()
    return header, n_lines


def _csv_reference(path: Path, header: dict[str, str], key: str, override) -> float:
    if override is not None:
        return float(override)
    if key not in header:
        raise AeroFileError(f"{path}: no reference value {key}: add a line '# {key} = ...' or pass {key}=")
    try:
        return float(header[key])
    except ValueError:
        raise AeroFileError(f"{path}: {key} = {header[key]!r} is not a number") from None


def read_aero_csv(
    path, *, reference_area_m2=None, reference_length_m=None, moment_reference_m=None, source=None
) -> AeroTables:
    """Body table from a long-format CSV file, one row per grid point, rows in any order.

    Layout::

        # reference_area_m2 = 0.01767      (S [m²])
        # reference_length_m = 0.15        (d [m])
        # moment_reference_m = 1.49        (moment point, from the nose tip [m])
        # source = OpenRocket 23.09 export (optional, one line)
        mach,alpha_deg,CA,CN,Cm
        0.1,0,0.45,0,0
        ...

    Axis columns: any non-empty subset of ``alpha_deg``, ``beta_deg`` [deg], ``mach``,
    ``altitude_m`` [m], each with >= 2 distinct values; the rows must cover every combination
    exactly once. Coefficient columns: names of ``BODY_COEFFS`` (case matters: CN ≠ Cn) in the
    conventions of ``aero.tables``; a coefficient without a column is 0. CA is required, and so
    are CN, Cm with an alpha axis and CY, Cn with a beta axis (a table over an angle that misses
    the force and moment the angle drives is taken for a mistake). Keyword arguments override
    the ``#`` header; other ``#`` lines at the top are free comments.
    """
    import pandas as pd  # here, not at import: ~0.2 s before the first flight of a campaign without CSV tables

    path = _existing(path)
    try:
        header, n_comment_lines = _csv_header(path)
    except UnicodeDecodeError:
        raise AeroFileError(f"{path}: not a UTF-8 text file") from None
    overrides = dict(zip(REFERENCE_KEYS, (reference_area_m2, reference_length_m, moment_reference_m)))
    reference = [_csv_reference(path, header, key, overrides[key]) for key in REFERENCE_KEYS]
    try:
        frame = pd.read_csv(
            path, encoding="utf-8-sig", skiprows=n_comment_lines, skipinitialspace=True, skip_blank_lines=False
        )
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as err:
        raise AeroFileError(f"{path}: {' '.join(str(err).split())}") from None
    frame.columns = [str(c).strip() for c in frame.columns]
    frame = frame.dropna(how="all")  # blank lines; the index still counts every line
    line = n_comment_lines + 2 + frame.index.to_numpy()  # file line (1-based) of each row
    axis_of = {column: axis for axis, column in CSV_AXIS_COLUMNS.items()}
    for column in frame.columns:
        if column not in axis_of and column not in BODY_COEFFS:
            raise AeroFileError(
                f"{path}:{n_comment_lines + 1}: unknown column {column!r}; axes are "
                f"{', '.join(CSV_AXIS_COLUMNS.values())}, coefficients {', '.join(BODY_COEFFS)}"
            )
    axis_names = tuple(axis_of[c] for c in frame.columns if c in axis_of)
    if not axis_names:
        raise AeroFileError(f"{path}: no axis column; expected some of {', '.join(CSV_AXIS_COLUMNS.values())}")
    required = ("CA",) + sum((CSV_REQUIRED.get(axis, ()) for axis in axis_names), ())
    missing = [name for name in required if name not in frame.columns]
    if missing:
        raise AeroFileError(
            f"{path}: missing column {', '.join(missing)} "
            "(CA is required, CN and Cm with alpha_deg, CY and Cn with beta_deg)"
        )

    def numbers(column: str) -> np.ndarray:
        x = pd.to_numeric(frame[column], errors="coerce").to_numpy(dtype=np.float64)
        bad = np.flatnonzero(~np.isfinite(x))
        if bad.size:
            raw = frame[column].iloc[bad[0]]
            got = "nothing" if pd.isna(raw) else repr(raw)
            raise AeroFileError(f"{path}:{line[bad[0]]}: column {column!r}: expected a finite number, got {got}")
        return x

    axes, indices = [], []
    for name in axis_names:
        axis, index = np.unique(numbers(CSV_AXIS_COLUMNS[name]), return_inverse=True)
        if axis.size < 2:
            raise AeroFileError(
                f"{path}: column {CSV_AXIS_COLUMNS[name]!r} has < 2 distinct values; leave it out instead"
            )
        axes.append(axis)
        indices.append(index)
    grid = tuple(a.size for a in axes)
    n_points = math.prod(grid)
    point = np.ravel_multi_index(indices, grid)  # flat grid index of each row
    repeated = np.flatnonzero(np.bincount(point, minlength=n_points) > 1)
    if repeated.size:
        first, second = line[point == repeated[0]][:2]
        raise AeroFileError(f"{path}:{second}: repeats the grid point of line {first}")
    if point.size < n_points:
        gap = np.unravel_index(np.setdiff1d(np.arange(n_points), point)[0], grid)
        where = ", ".join(f"{CSV_AXIS_COLUMNS[n]} = {a[i]:g}" for n, a, i in zip(axis_names, axes, gap))
        raise AeroFileError(
            f"{path}: the rows do not form a full grid: "
            f"{n_points - point.size} of {n_points} points missing, e.g. {where}"
        )
    values = np.zeros((n_points, len(BODY_COEFFS)))
    for k, name in enumerate(BODY_COEFFS):
        if name in frame.columns:
            values[point, k] = numbers(name)
    axes = [np.deg2rad(a) if AXIS_UNITS[n] == "rad" else a for n, a in zip(axis_names, axes)]
    body = GriddedCoefficients(axis_names, tuple(axes), BODY_COEFFS, values.reshape(grid + (len(BODY_COEFFS),)))
    return AeroTables(*reference, body, source=source or header.get("source") or f"CSV file {path.name}")


def write_aero_csv(path, tables: AeroTables) -> None:
    """Writes the body table in ``read_aero_csv``'s layout (all coefficient columns, angles in
    degrees), atomically. Canard panels have no CSV form: tables with canards raise ValueError."""
    if tables.canards is not None:
        raise ValueError("canard panel tables cannot be written to CSV; save the tables to HDF5 instead")
    import pandas as pd  # as in ``read_aero_csv``

    body = tables.body
    points = np.meshgrid(*body.axes, indexing="ij")
    columns = {
        CSV_AXIS_COLUMNS[name]: (np.rad2deg(x) if AXIS_UNITS[name] == "rad" else x).ravel()
        for name, x in zip(body.axis_names, points)
    }
    columns.update(zip(BODY_COEFFS, body.values.reshape(-1, len(BODY_COEFFS)).T))
    with replacing(path) as partial, open(partial, "w", encoding="utf-8", newline="") as file:
        file.write(f"# rocketmc aerodynamic table, written by rocketmc {__version__}\n")
        file.writelines(f"# {key} = {float(getattr(tables, key))!r}\n" for key in REFERENCE_KEYS)
        if tables.source:
            file.write(f"# source = {' '.join(tables.source.splitlines())}\n")
        pd.DataFrame(columns).to_csv(file, index=False, lineterminator="\n")


# --- any file ------------------------------------------------------------------------------------


def load_aero(path, **reference) -> AeroTables:
    """``AeroTables`` from an .h5/.hdf5, .csv or DATCOM .mat file, by extension.

    ``reference``: ``reference_area_m2``, ``reference_length_m``, ``moment_reference_m``,
    ``source``; they override a CSV file's header, are required for a .mat (which does not record
    them, ``source`` aside) and refused for HDF5 (which stores its own: move the moment point with
    ``AeroTables.re_referenced`` instead).
    """
    path = _existing(path)
    reference = {k: v for k, v in reference.items() if v is not None}
    suffix = path.suffix.lower()
    if suffix in (".h5", ".hdf5"):
        if reference:
            raise AeroFileError(
                f"{path}: an HDF5 aero file carries its own reference values; got {', '.join(reference)}"
            )
        return load_aero_tables(path)
    if suffix == ".csv":
        return read_aero_csv(path, **reference)
    if suffix == ".mat":
        missing = [key for key in REFERENCE_KEYS if key not in reference]
        if missing:
            raise AeroFileError(
                f"{path}: a DATCOM .mat file does not record its reference values; pass {', '.join(missing)}"
            )
        return datcom_tables(path, **reference)
    raise AeroFileError(f"{path}: unknown aerodynamic file type {path.suffix!r}; expected .h5, .hdf5, .csv or .mat")

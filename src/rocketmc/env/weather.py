"""The day's atmosphere from real data, on the host: a sounding (University of Wyoming text or CSV) or a
reanalysis/forecast file on pressure levels (ERA5 or GFS netCDF-3, read by ``scipy.io.netcdf_file``, or
netCDF-4/HDF5, read by ``h5py``).

Every reader returns a ``Weather``: levels in increasing height, each with its geopotential height,
temperature, pressure and wind. Heights are geopotential (H = Φ/g0 from the geopotential Φ, as a sounding's
HGHT is): ``geometric_altitude`` converts them, with the ISA's Earth radius. Errors are ``WeatherError``
naming the file and what is wrong, and which campaign field to blame.
"""

from __future__ import annotations

import re
from datetime import datetime, timedelta, timezone
from pathlib import Path
from typing import NamedTuple

import h5py
import numpy as np

from .atmosphere import G0, R_EARTH_GEOPOTENTIAL
from .wind import read_csv_columns

KNOT_MPS = 1852.0 / 3600.0  # one knot [m/s]
CELSIUS_K = 273.15  # 0 °C [K]
MIN_TEMPERATURE_K = 150.0  # colder than any air below 50 km (the mesopause reaches ~130 K at 85 km)
MAX_TEMPERATURE_K = 350.0  # hotter than any air measured (57 °C at the surface)
UWYO_COLUMN_WIDTH = 7  # characters per column of the University of Wyoming text list
UWYO_COLUMNS = ("PRES", "HGHT", "TEMP", "DRCT", "SKNT")
"""The columns read from a UWyo sounding: pressure [hPa], geopotential height [m], temperature [°C], the
direction the wind blows from [deg] and its speed [knot]; a level missing any of them is skipped."""
SOUNDING_CSV_COLUMNS = (("geopotential_height_m", "altitude_msl_m"), ("pressure_pa",), ("temperature_k",),
                        ("speed_mps",), ("from_deg",))  # fmt: skip
"""The columns of a CSV sounding: the height (geopotential, or geometric above mean sea level), pressure [Pa],
temperature [K], wind speed [m/s] and the direction it blows from [deg]."""


class WeatherError(ValueError):
    """A weather file that cannot be used; ``field`` names the campaign key to blame (``file``, ``time_utc``)."""

    def __init__(self, message: str, field: str = "file"):
        super().__init__(message)
        self.field = field


class Weather(NamedTuple):
    """One profile, K ≥ 2 levels in strictly increasing height: geopotential_height_m [m], temperature_k [K],
    pressure_pa [Pa], speed_mps [m/s] and from_rad (the direction the wind blows from, clockwise from north
    [rad]), each (K,); time_utc: the analysis time used (None for a sounding, which has its own)."""

    geopotential_height_m: np.ndarray
    temperature_k: np.ndarray
    pressure_pa: np.ndarray
    speed_mps: np.ndarray
    from_rad: np.ndarray
    time_utc: datetime | None = None


def geometric_altitude(geopotential_height_m):
    """Geometric altitude above mean sea level [m] of a geopotential height [m]: z = R·H/(R − H), R the ISA's
    Earth radius (the inverse of ``atmosphere.geopotential_altitude``; z − H is 1.4 m at 3 km)."""
    return R_EARTH_GEOPOTENTIAL * geopotential_height_m / (R_EARTH_GEOPOTENTIAL - geopotential_height_m)


def speed_from(east_mps, north_mps) -> tuple[np.ndarray, np.ndarray]:
    """Speed [m/s] and meteorological direction [rad, in [0, 2π)] of a wind of components u (east) and v (north)."""
    return np.hypot(east_mps, north_mps), np.mod(np.arctan2(-east_mps, -north_mps), 2.0 * np.pi)


def read_weather(path, latitude_deg: float, longitude_deg: float, time_utc: datetime | None = None,
                 grid: str | None = None) -> Weather:  # fmt: skip
    """The profile in ``path``, told apart by its content: netCDF-3 or HDF5 (netCDF-4) files are read at the
    site (``grid``: ``"nearest"`` grid point or ``"bilinear"`` between the four around it, the default) and at
    the time in the
    file nearest to ``time_utc`` (required for them); any other file is a sounding: UWyo text if it has a
    PRES ... HGHT header line, else CSV (``SOUNDING_CSV_COLUMNS``)."""
    path = Path(path)
    try:
        with path.open("rb") as f:
            magic = f.read(8)
    except OSError as err:
        raise WeatherError(f"{path}: cannot be read ({err.strerror})") from None
    if magic[:3] == b"CDF" or magic == b"\x89HDF\r\n\x1a\n":
        if time_utc is None:
            raise WeatherError(f"{path}: a netCDF file holds many times; give the launch's time_utc", "time_utc")
        weather = _read_netcdf(path, magic[:3] == b"CDF", latitude_deg, longitude_deg, time_utc, grid or "bilinear")
        return _checked(path, weather, "z")
    for name, value in (("time_utc", time_utc), ("grid", grid)):
        if value is not None:
            raise WeatherError(f"{path}: a sounding is one profile; {name} applies to netCDF files only", name)
    try:
        text = path.read_text(encoding="utf-8-sig")
    except UnicodeDecodeError:
        raise WeatherError(f"{path}: not a UTF-8 text file, a netCDF-3 or a netCDF-4 (HDF5) file") from None
    lines = text.splitlines()
    header = next((i for i, line in enumerate(lines) if {"PRES", "HGHT"} <= set(line.split())), None)
    if header is not None:
        return _checked(path, _read_uwyo(path, lines, header), "HGHT")
    return _checked(path, *_read_sounding_csv(path))


def _checked(path: Path, weather: Weather, height: str) -> Weather:
    """``weather`` if it is a usable profile, else WeatherError naming what is wrong; ``height``: the name of the
    file's height field."""
    h, t, p = weather.geopotential_height_m, weather.temperature_k, weather.pressure_pa
    if len(h) < 2:
        raise WeatherError(f"{path}: needs at least 2 levels with a height, pressure, temperature and wind")
    if not all(np.all(np.isfinite(a)) for a in weather[:5]):
        raise WeatherError(f"{path}: a level's height, pressure, temperature or wind is not a finite number")
    if not np.all(np.diff(h) > 0):
        k = int(np.argmin(np.diff(h) > 0))
        raise WeatherError(f"{path}: {height} must increase strictly with height (from the lowest pressure level "
                           f"up), got {h[k]:g} m then {h[k + 1]:g} m")  # fmt: skip
    if not np.all(np.diff(p) < 0):
        raise WeatherError(f"{path}: pressure must decrease with height")
    if p[-1] <= 0 or t.min() < MIN_TEMPERATURE_K or t.max() > MAX_TEMPERATURE_K:
        raise WeatherError(f"{path}: pressures must be positive and temperatures within {MIN_TEMPERATURE_K:g} to "
                           f"{MAX_TEMPERATURE_K:g} K, got {t.min():.1f} to {t.max():.1f} K")  # fmt: skip
    if np.any(weather.speed_mps < 0):
        raise WeatherError(f"{path}: wind speeds must not be negative")
    return weather


def _read_uwyo(path: Path, lines: list[str], header: int) -> Weather:
    """The University of Wyoming text list: after the header line (names right-aligned in 7-character columns),
    a units line between dashed lines, one level per line until a line that does not start with a number."""
    names = lines[header].split()
    missing = [c for c in UWYO_COLUMNS if c not in names]
    if missing:
        raise WeatherError(f"{path}: line {header + 1}: the sounding's header lacks {', '.join(missing)}")
    columns = [names.index(c) for c in UWYO_COLUMNS]
    rows, started = [], False
    for number, line in enumerate(lines[header + 1 :], start=header + 2):
        if not _starts_with_number(line):
            if started:
                break  # the table's end: a blank line, "Station information ...", "</PRE>"
            continue  # the units line and the dashed lines under the header
        started = True
        fields = [line[UWYO_COLUMN_WIDTH * k : UWYO_COLUMN_WIDTH * (k + 1)].strip() for k in columns]
        if "" in fields:
            continue  # a level without temperature or wind (e.g. below ground, or a mandatory level's height only)
        try:
            rows.append([float(x) for x in fields])
        except ValueError:
            bad = next(c for c, x in zip(UWYO_COLUMNS, fields) if not _is_number(x))
            raise WeatherError(f"{path}: line {number}: {bad} is not a number "
                               f"({fields[UWYO_COLUMNS.index(bad)]!r})") from None  # fmt: skip
    if not rows:
        raise WeatherError(f"{path}: no level with {', '.join(UWYO_COLUMNS)} under the header")
    pres, hght, temp, drct, sknt = np.array(rows).T
    return Weather(hght, temp + CELSIUS_K, pres * 100.0, sknt * KNOT_MPS, np.deg2rad(drct))


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _starts_with_number(line: str) -> bool:
    return bool(line.split()) and _is_number(line.split()[0])


def _read_sounding_csv(path: Path) -> tuple[Weather, str]:
    """A CSV sounding (``SOUNDING_CSV_COLUMNS``) and the name of its height column."""
    try:
        names, values = read_csv_columns(path, SOUNDING_CSV_COLUMNS)
    except ValueError as err:
        raise WeatherError(str(err)) from None
    height, pressure, temperature, speed, from_deg = values.T
    if names[0] == "altitude_msl_m":
        height = R_EARTH_GEOPOTENTIAL * height / (R_EARTH_GEOPOTENTIAL + height)  # geometric → geopotential
    return Weather(height, temperature, pressure, speed, np.deg2rad(from_deg)), names[0]


NETCDF_NAMES = {
    "level": ("level", "pressure_level", "isobaricInhPa", "lev"),
    "latitude": ("latitude", "lat"),
    "longitude": ("longitude", "lon"),
    "time": ("time", "valid_time"),
    "z": ("z", "gh"),
    "t": ("t",),
    "u": ("u",),
    "v": ("v",),
}
"""The names each needed netCDF variable may have (ERA5's, then GFS's through cfgrib): the pressure levels
[hPa or Pa], latitude and longitude [deg], time (CF units, "hours since 1900-01-01"), geopotential z
[m² s⁻²] or geopotential height gh [gpm], temperature t [K], wind components u (east) and v (north) [m/s]."""


class _Variable(NamedTuple):
    data: np.ndarray  # unpacked (scale_factor, add_offset), fill values as NaN
    dimensions: tuple[str, ...]  # a coordinate's is its own name
    units: str


def _unpacked(raw: np.ndarray, attrs) -> np.ndarray:
    """CF packing undone: raw·scale_factor + add_offset, _FillValue and missing_value made NaN."""
    data = np.asarray(raw, dtype=float)
    for key in ("_FillValue", "missing_value"):
        if key in attrs:
            data = np.where(raw == np.asarray(attrs[key]).ravel()[0], np.nan, data)
    return data * float(np.asarray(attrs.get("scale_factor", 1.0)).ravel()[0]) + float(
        np.asarray(attrs.get("add_offset", 0.0)).ravel()[0])


def _text(value) -> str:
    value = np.asarray(value).ravel()[0] if not isinstance(value, bytes | str) else value
    return value.decode() if isinstance(value, bytes) else str(value)


def _netcdf_variables(path: Path, classic: bool) -> dict[str, _Variable]:
    """The variables of NETCDF_NAMES found in the file, by their key there."""
    import scipy.io  # here, not at import: ~0.08 s before the first flight of a campaign without a weather file

    wanted = {name: key for key, names in NETCDF_NAMES.items() for name in names}
    found = {}
    try:
        if classic:
            with scipy.io.netcdf_file(path, "r", mmap=False) as f:
                for name, var in f.variables.items():
                    if name in wanted and wanted[name] not in found:
                        attrs = var._attributes
                        found[wanted[name]] = _Variable(_unpacked(var[...], attrs), tuple(var.dimensions),
                                                        _text(attrs.get("units", b"")))  # fmt: skip
        else:
            with h5py.File(path, "r") as f:
                for name in f:
                    var = f[name]
                    if name in wanted and wanted[name] not in found and isinstance(var, h5py.Dataset):
                        dims = tuple(var.dims[i][0].name.lstrip("/") if len(var.dims[i]) else name
                                     for i in range(var.ndim))  # a dimension scale has none attached: its own
                        found[wanted[name]] = _Variable(_unpacked(var[()], var.attrs), dims,
                                                        _text(var.attrs.get("units", b"")))  # fmt: skip
    except (OSError, ValueError, TypeError, KeyError) as err:
        raise WeatherError(f"{path}: not a readable netCDF file ({err})") from None
    missing = [f"{key} ({' or '.join(NETCDF_NAMES[key])})" for key in NETCDF_NAMES if key not in found]
    if missing:
        raise WeatherError(f"{path}: no variable {', '.join(missing)}")
    return found


def _times(path: Path, time: _Variable) -> list[datetime]:
    """The file's times (UTC) from CF units "<unit> since <date>[ <time>]"."""
    match = re.fullmatch(r"(seconds|minutes|hours|days) since (\d{4}-\d{1,2}-\d{1,2})[ T]?([\d:.]*)\s*(UTC|Z)?",
                         time.units.strip())  # fmt: skip
    if match is None or time.data.ndim != 1:
        raise WeatherError(f"{path}: time: expected units '<hours|...> since <date>', got {time.units!r}")
    unit, date, clock = match.group(1), match.group(2), match.group(3) or "0:0:0"
    hms = [float(x) for x in (clock.split(":") + ["0", "0"])[:3]]
    epoch = datetime.fromisoformat(date).replace(tzinfo=timezone.utc) + timedelta(
        hours=hms[0], minutes=hms[1], seconds=hms[2])
    return [epoch + timedelta(**{unit: float(x)}) for x in time.data]


def _axis_weights(path: Path, axis: np.ndarray, value: float, name: str, grid: str) -> list[tuple[int, float]]:
    """(index, weight) pairs interpolating ``axis`` (monotonic) at ``value``: the nearest point, or the two
    around it linearly."""
    lo, hi = min(axis[0], axis[-1]), max(axis[0], axis[-1])
    if not lo <= value <= hi:
        raise WeatherError(f"{path}: the site's {name} {value:g}° is outside the file's grid ({lo:g} to {hi:g}°)")
    if grid == "nearest" or len(axis) == 1:
        return [(int(np.argmin(np.abs(axis - value))), 1.0)]
    order = np.argsort(axis)
    sorted_axis = axis[order]
    k = int(np.clip(np.searchsorted(sorted_axis, value, side="right") - 1, 0, len(axis) - 2))
    s = (value - sorted_axis[k]) / (sorted_axis[k + 1] - sorted_axis[k])
    return [(int(order[k]), 1.0 - s), (int(order[k + 1]), s)]


def _read_netcdf(path: Path, classic: bool, latitude_deg: float, longitude_deg: float, time_utc: datetime,
                 grid: str) -> Weather:  # fmt: skip
    v = _netcdf_variables(path, classic)
    times = _times(path, v["time"])
    if not times[0] <= time_utc <= times[-1]:
        raise WeatherError(f"{path}: {time_utc:%Y-%m-%dT%H:%M}Z is outside the file's times "
                           f"({times[0]:%Y-%m-%dT%H:%M} to {times[-1]:%Y-%m-%dT%H:%M}Z)", "time_utc")  # fmt: skip
    nearest_time = int(np.argmin([abs((t - time_utc).total_seconds()) for t in times]))
    longitudes = v["longitude"].data
    if longitudes.max() > 180.0 and longitude_deg < 0.0:  # a grid in 0..360° east
        longitude_deg += 360.0
    lat = _axis_weights(path, v["latitude"].data, latitude_deg, "latitude", grid)
    lon = _axis_weights(path, longitudes, longitude_deg, "longitude", grid)
    axes = [v[key].dimensions[0] for key in ("time", "level", "latitude", "longitude")]

    def at_site(key: str) -> np.ndarray:
        """The variable at the chosen time and the site, one value per level."""
        var = v[key]
        try:
            order = [list(var.dimensions).index(d) for d in axes]
        except ValueError:
            raise WeatherError(f"{path}: {key}: expected dimensions {', '.join(axes)}, found "
                               f"{', '.join(var.dimensions) or 'none'}") from None  # fmt: skip
        data = np.transpose(var.data, order)[nearest_time]
        return sum(wi * wj * data[:, i, j] for i, wi in lat for j, wj in lon)

    height = at_site("z") if v["z"].units.startswith("gpm") or v["z"].units == "m" else at_site("z") / G0
    pressure = v["level"].data * (1.0 if v["level"].units.strip() == "Pa" else 100.0)  # hPa, millibars
    temperature, east, north = at_site("t"), at_site("u"), at_site("v")
    keep = np.isfinite(height) & np.isfinite(temperature) & np.isfinite(east) & np.isfinite(north)
    order = np.argsort(-pressure[keep], kind="stable")  # the highest pressure, the lowest level, first
    speed, from_rad = speed_from(east[keep][order], north[keep][order])
    return Weather(height[keep][order], temperature[keep][order], pressure[keep][order], speed, from_rad,
                   times[nearest_time])  # fmt: skip

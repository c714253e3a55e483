"""Write ``src/rocketmc/data/weather/euroc_2023-10-13_12z_era5_uwyo.txt``: a SYNTHETIC sounding in the
University of Wyoming text-list layout, built from the vendored ERA5 extract (netCDF-3) at its grid point
nearest to the EuRoC pad at 2023-10-13 12:00 UTC, rounded as UWyo rounds (hPa to 0.1, m, °C to 0.1, deg,
knots). No balloon flew it: it is there to test and demonstrate the sounding reader."""

from datetime import datetime, timezone
from pathlib import Path

import numpy as np

from rocketmc.env.weather import CELSIUS_K, KNOT_MPS, read_weather

DATA = Path(__file__).parents[2] / "src" / "rocketmc" / "data" / "weather"
TIME = datetime(2023, 10, 13, 12, tzinfo=timezone.utc)
SITE = (39.3903, -8.2892)  # EuRoC's pad (campaigns/lynx_euroc_2021.toml)
TOP_PA = 10_000.0  # 100 hPa (~16 km), where most radiosondes' wind records thin out

weather = read_weather(DATA / "euroc_2023_all_windows.nc", *SITE, TIME, "nearest")
names = "PRES HGHT TEMP DWPT RELH MIXR DRCT SKNT THTA THTE THTV".split()
units = "hPa m C C % g/kg deg knot K K K".split()
dashes = "-" * 7 * len(names)
lines = [
    "99999 EUROC SYNTHETIC sounding (ERA5 at 39.50N 8.25W, not an observation) at 12Z 13 Oct 2023",
    "",
    dashes,
    "".join(f"{n:>7}" for n in names),
    "".join(f"{u:>7}" for u in units),
    dashes,
]
for h, t, p, speed, from_rad in zip(*weather[:5]):
    if p < TOP_PA:
        break
    theta = t * (100_000.0 / p) ** 0.2857  # potential temperature, R/cp of dry air
    lines.append(f"{p / 100:7.1f}{h:7.0f}{t - CELSIUS_K:7.1f}{'':21}{np.rad2deg(from_rad) % 360:7.0f}"
                 f"{speed / KNOT_MPS:7.0f}{theta:7.1f}")
lines += ["", "Station information and sounding indices", "                         Station identifier: EUROC",
          "                     Observation time: 231013/1200", "      Source: ERA5 (Copernicus C3S), synthetic", ""]
(DATA / "euroc_2023-10-13_12z_era5_uwyo.txt").write_text("\n".join(lines))

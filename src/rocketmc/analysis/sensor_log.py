"""Sensor logs in the layout of the vendored Roccaraso 2021 Lynx log (``data/flights/roccaraso_2021``),
so that a simulated log (``rocketmc sensors simulate``) and the real one compare channel by channel; on
the host (numpy, pandas, scipy, matplotlib).

A log is a directory holding the three CSV files of ``LOG_FILES``, each with a ``sample`` index from 0,
the nominal time ``t_nominal_s`` = sample × period [s] since liftoff (3 decimals) and the values. The
file names are fixed whatever the rate: a barometer simulated at 50 Hz still writes
``baro_ms5803_66hz.csv``; the reader takes each period from the file's ``t_nominal_s``. The real log's
pitot file is not part of a sensor log.

Units and axes, from the real log's SOURCE.md and what its data show:

- imu (BMX160, 50 Hz; each sample the mean of a FIFO, calibrated and rotated into the body frame):
  ``acc_*`` specific force [m/s²] (+9.77 along x on the pad: x toward the nose), ``gyro_*`` body rates
  [rad/s], ``mag_*`` magnetic field, "most likely" µT (SOURCE.md; the simulator's field is in T). The
  real magnitude reads 25 µT (24–27 µT in flight, 30 µT at sample 0) where IGRF-13 gives 46.8 µT at
  Roccaraso, and its dip against the measured gravity 65° where IGRF-13 gives 58°: trust its direction
  roughly, not its scale. The source does not say where y and z point about the rocket's axis. The
  three sensors share one right-handed frame with right-hand-rule rates: under the drogue the
  measured field changes as −ω × B (least-squares slopes 1.11, 1.03, 0.97 on x, y, z), and the
  specific force and field give the same dip on the pad and after landing (64.6°, 65.3°), which
  flipping any one accelerometer axis breaks.
- baro (MS5803, 15 ms period, 66.7 Hz): ``pressure_pa`` [Pa]. In the real log every 6th sample repeats
  the one before (the sensor delivered ~55.6 Hz), so 1/6 of its steps are zero.
- gnss (NEO-M9N, 25 Hz): ``lat_deg``, ``lon_deg`` [deg, WGS84; float32 in the real log: steps of
  0.4 m north, 0.08 m east], ``vel_{north,east,down}_mps`` [m/s, NED], ``num_sats``.
"""

from __future__ import annotations

import math
import os
from importlib.resources.abc import Traversable
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.figure import Figure
from scipy.stats import median_abs_deviation

from ..files import replacing
from .flight_log import read_stream
from .plots import save_figure

LOG_FILES = {
    "imu": ("imu_bmx160_50hz.csv", ("sample", "t_nominal_s", "acc_x_mps2", "acc_y_mps2", "acc_z_mps2",
                                    "gyro_x_radps", "gyro_y_radps", "gyro_z_radps", "mag_x", "mag_y", "mag_z")),
    "baro": ("baro_ms5803_66hz.csv", ("sample", "t_nominal_s", "pressure_pa")),
    "gnss": ("gps_neom9n_25hz.csv", ("sample", "t_nominal_s", "lat_deg", "lon_deg", "vel_north_mps",
                                     "vel_east_mps", "vel_down_mps", "num_sats")),
}  # fmt: skip
"""Stream → (file name, CSV header exactly as in the real log)."""

CHANNELS = {
    **{f"acc_{a}_mps2": ("imu", f"specific force {a} [m/s²]") for a in "xyz"},
    **{f"gyro_{a}_radps": ("imu", f"body rate {a} [rad/s]") for a in "xyz"},
    **{f"mag_{a}": ("imu", f"magnetic field {a} [µT]") for a in "xyz"},
    **{f"vel_{d}_mps": ("gnss", f"GNSS velocity {d} [m/s]") for d in ("north", "east", "down")},
    "pressure_pa": ("baro", "pressure [Pa]"),
}
"""Compared channel → (stream, label with unit), in the order of the comparison figure's panels."""


def write_sensor_log(directory: str | os.PathLike, streams: dict[str, pd.DataFrame]) -> None:
    """Write each stream of ``streams`` (names of ``LOG_FILES``: a frame of ``t_s`` [s since liftoff, its first
    sample's time + k × period] and the header's value columns) as its CSV in ``directory`` (created if need be):
    ``sample`` from 0, ``t_nominal_s`` to 1 ms, values to 10 significant digits."""
    root = Path(directory)
    root.mkdir(parents=True, exist_ok=True)
    for name, frame in streams.items():
        if name not in LOG_FILES:
            raise ValueError(f"sensor log: unknown stream {name!r} (known: {', '.join(LOG_FILES)})")
        file, header = LOG_FILES[name]
        if missing := [c for c in ("t_s", *header[2:]) if c not in frame]:
            raise ValueError(f"sensor log: stream {name!r} lacks columns {', '.join(missing)}")
        table = pd.DataFrame({"sample": np.arange(len(frame)), "t_nominal_s": frame["t_s"].map("{:.3f}".format),
                              **{c: frame[c].map("{:.10g}".format) for c in header[2:]}})  # fmt: skip
        with replacing(root / file) as partial:
            table.to_csv(partial, index=False, lineterminator="\n")


def read_sensor_log(directory: str | os.PathLike | Traversable) -> dict[str, pd.DataFrame]:
    """The three streams of a sensor log (the real one: ``flight_log.ROCCARASO_2021``) as frames of
    ``t_s`` = the first sample's time + sample × period [s] and the value columns named as in the CSV headers
    (a simulated log's ``num_sats`` is NaN: not modelled)."""
    root = Path(directory) if isinstance(directory, (str, os.PathLike)) else directory
    return {name: read_stream(root / file, None, {c: c for c in header[2:]}, optional=("num_sats",))
            for name, (file, header) in LOG_FILES.items()}  # fmt: skip


def high_frequency_noise(frame: pd.DataFrame, columns, start_s: float, end_s: float, *, order: int = 1,
                         robust: bool = True) -> dict[str, float]:  # fmt: skip
    """White noise per sample [the column's unit] of each of ``columns`` over start_s ≤ t_s ≤ end_s.

    The spread of the ``order``-th differences (1: x_{k+1} − x_k; 2: x_{k+2} − 2x_{k+1} + x_k) over
    √C(2·order, order) (√2, √6): the noise's standard deviation where the signal is smooth at the
    sample rate. Second differences also cancel a signal's slope changes (roll, coning), which first
    differences keep. Spread: ``robust`` 1.4826 × the median absolute deviation (the standard deviation
    for normal noise), which transients in the window (shocks, pressure spikes, GNSS jumps) barely
    move; else the standard deviation.
    """
    t = frame["t_s"].to_numpy()
    inside = (t >= start_s) & (t <= end_s)
    if inside.sum() < order + 3:
        raise ValueError(f"high_frequency_noise: {inside.sum()} samples in {start_s}–{end_s} s, {order + 3} needed")
    noise = {}
    for column in columns:
        d = np.diff(frame[column].to_numpy(dtype=float)[inside], n=order)
        spread = median_abs_deviation(d, scale="normal") if robust else np.std(d, ddof=1)
        noise[column] = float(spread / math.sqrt(math.comb(2 * order, order)))
    return noise


def noise_comparison(simulated: dict[str, pd.DataFrame], real: dict[str, pd.DataFrame],
                     windows: dict[str, tuple[float, float]], *, order: int = 1,
                     robust: bool = True) -> pd.DataFrame:  # fmt: skip
    """``high_frequency_noise`` of each ``CHANNELS`` channel in both logs (read_sensor_log's frames) per
    window ``{name: (start_s, end_s)}`` [s since liftoff]: columns window, channel, label (with the
    unit), simulated, real and ratio (simulated / real)."""
    rows = []
    for window, (start, end) in windows.items():
        for channel, (stream, label) in CHANNELS.items():
            sim, meas = (high_frequency_noise(log[stream], [channel], start, end, order=order, robust=robust)[channel]
                         for log in (simulated, real))  # fmt: skip
            rows.append({"window": window, "channel": channel, "label": label, "simulated": sim, "real": meas,
                         "ratio": sim / meas})  # fmt: skip
    return pd.DataFrame(rows)


def plot_log_comparison(simulated: dict[str, pd.DataFrame], real: dict[str, pd.DataFrame],
                        path: str | Path | None, channels=None) -> Figure:  # fmt: skip
    """The simulated (orange) and real (black) series of ``channels`` (default: all ``CHANNELS``) against
    time since liftoff [s], one panel each, three per row on a shared time axis; saved to ``path`` if given."""
    channels = list(CHANNELS) if channels is None else list(channels)
    if unknown := [c for c in channels if c not in CHANNELS]:
        raise ValueError(f"plot_log_comparison: unknown channels {', '.join(unknown)} (known: {', '.join(CHANNELS)})")
    rows = math.ceil(len(channels) / 3)
    fig = Figure(figsize=(15.0, 2.6 * rows + 0.6), layout="constrained")
    axes = fig.subplots(rows, 3, sharex=True, squeeze=False).ravel()
    for ax, channel in zip(axes, channels):
        stream, label = CHANNELS[channel]
        ax.plot(real[stream]["t_s"], real[stream][channel], color="black", linewidth=0.6, label="real")
        ax.plot(simulated[stream]["t_s"], simulated[stream][channel], color="tab:orange", linewidth=0.6, alpha=0.8,
                label="simulated")  # fmt: skip
        ax.set_title(label, fontsize="medium")
        ax.grid(True, alpha=0.4)
    for ax in axes[len(channels) :]:
        ax.remove()
    for ax in axes[max(len(channels) - 3, 0) : len(channels)]:  # the lowest panel of each column
        ax.xaxis.set_tick_params(labelbottom=True)
        ax.set_xlabel("time since liftoff [s]")
    axes[0].legend(fontsize="small")
    fig.suptitle("Sensor logs: simulated and real")
    if path is not None:
        save_figure(fig, path)
    return fig

"""Sensor logs in the Roccaraso layout: headers and values against the vendored CSVs themselves (read
with the csv module), the writer's round trip, the noise estimator against white noise of known σ,
the comparison table and figure."""

import csv

import numpy as np
import pandas as pd
import pytest

from rocketmc.analysis.flight_log import ROCCARASO_2021, load_roccaraso_2021
from rocketmc.analysis.sensor_log import (
    CHANNELS,
    LOG_FILES,
    high_frequency_noise,
    noise_comparison,
    plot_log_comparison,
    read_sensor_log,
    write_sensor_log,
)

PERIODS_S = {"imu": 0.020, "baro": 0.015, "gnss": 0.040}  # SOURCE.md's header comments


def _csv(directory, file):
    with (directory / file).open() as f:
        return list(csv.reader(f))


@pytest.fixture(scope="module")
def real():
    return read_sensor_log(ROCCARASO_2021)


@pytest.mark.parametrize("stream", LOG_FILES)
def test_headers_and_values_are_the_real_log(real, stream):
    file, header = LOG_FILES[stream]
    rows = _csv(ROCCARASO_2021, file)
    assert tuple(rows[0]) == header
    frame = real[stream]
    assert list(frame.columns) == ["t_s", *header[2:]] and len(frame) == len(rows) - 1
    # The period comes from the last t_nominal_s (1 ms over thousands of rows): 1e-12 is rounding.
    np.testing.assert_allclose(frame.t_s, np.arange(len(frame)) * PERIODS_S[stream], rtol=0, atol=1e-12)
    np.testing.assert_array_equal(frame.iloc[:, 1:].to_numpy(), np.array(rows[1:], dtype=float)[:, 2:])


def test_same_values_as_the_flight_log_reader(real):
    log = load_roccaraso_2021()
    np.testing.assert_array_equal(real["imu"].iloc[:, 1:].to_numpy(), log.imu.iloc[:, 1:].to_numpy())
    np.testing.assert_array_equal(real["baro"].pressure_pa, log.baro.pressure_pa)
    np.testing.assert_array_equal(real["gnss"].vel_down_mps, log.gnss.v_down_mps)


def test_rewritten_real_log_reads_back_bit_identical(real, tmp_path):
    # Every value of the real log has at most 9 significant digits (float32 printed), so 10 digits
    # give back the same float64; sample and t_nominal_s come out as the original text.
    write_sensor_log(tmp_path / "log", real)
    again = read_sensor_log(tmp_path / "log")
    for stream, (file, header) in LOG_FILES.items():
        pd.testing.assert_frame_equal(again[stream], real[stream], check_exact=True)
        original, written = _csv(ROCCARASO_2021, file), _csv(tmp_path / "log", file)
        assert tuple(written[0]) == header and [r[:2] for r in written] == [r[:2] for r in original]


def test_simulated_rates_keep_the_file_names(tmp_path):
    # A barometer at 50 Hz in baro_ms5803_66hz.csv; 10 significant digits: 5e-10 relative.
    rng = np.random.default_rng(5)
    t = np.arange(3000) * 0.02
    baro = pd.DataFrame({"t_s": t, "pressure_pa": 85000.0 - 5.0 * t + rng.normal(0.0, 2.0, t.size)})
    write_sensor_log(tmp_path, {"baro": baro})
    assert [p.name for p in tmp_path.iterdir()] == ["baro_ms5803_66hz.csv"]
    rows = _csv(tmp_path, "baro_ms5803_66hz.csv")
    assert rows[0] == ["sample", "t_nominal_s", "pressure_pa"] and rows[-1][:2] == ["2999", "59.980"]
    back = pd.read_csv(tmp_path / "baro_ms5803_66hz.csv")
    np.testing.assert_allclose(back.pressure_pa, baro.pressure_pa, rtol=5e-10, atol=0)


def test_writer_rejects_unknown_streams_and_missing_columns(tmp_path):
    with pytest.raises(ValueError, match="pitot"):
        write_sensor_log(tmp_path, {"pitot": pd.DataFrame({"t_s": [0.0, 0.024]})})
    with pytest.raises(ValueError, match="mag_z"):
        imu = pd.DataFrame({c: [0.0, 1.0] for c in ("t_s", *LOG_FILES["imu"][1][2:-1])})
        write_sensor_log(tmp_path, {"imu": imu})


N_NOISE, SIGMA = 20_000, 0.2
# Sampling error: over 300 seeds of these 20 000 samples the relative error of the estimate had a
# standard deviation of 0.9 % (median absolute deviation; 1.17/√n for independent samples, the
# differences' correlation adds 8 %) and 0.6 % (standard deviation), the largest 2.9 %: 4 % is more
# than 4σ. The signals are smooth enough to add under 0.1 % (below).


@pytest.fixture(scope="module")
def noisy():
    rng = np.random.default_rng(11)
    t = np.arange(N_NOISE) * 0.02
    noise = SIGMA * rng.standard_normal(N_NOISE)
    spikes = np.zeros(N_NOISE)
    spikes[rng.choice(N_NOISE, 20, replace=False)] = 50.0 * SIGMA  # shocks: 1 sample in 1000
    return pd.DataFrame({
        "t_s": t,
        # first differences 0.02·(−3 + 2e-3·t): their spread 0.005 adds 0.02 % to the noise's 0.28
        "drift": 85000.0 - 3.0 * t + 1e-3 * t**2 + noise,
        # a roll at 0.5 Hz: first differences swing by ±0.31, second ones by ±0.02 (0.1 % added)
        "roll": 5.0 * np.sin(np.pi * t) + noise,
        "shocks": 85000.0 - 3.0 * t + 1e-3 * t**2 + noise + spikes,
    })  # fmt: skip


@pytest.mark.parametrize("robust", [True, False])
def test_noise_of_a_smooth_signal(noisy, robust):
    noise = high_frequency_noise(noisy, ["drift"], 0.0, 400.0, robust=robust)
    assert noise["drift"] == pytest.approx(SIGMA, rel=0.04)


def test_second_differences_cancel_a_roll(noisy):
    assert high_frequency_noise(noisy, ["roll"], 0.0, 400.0, order=2)["roll"] == pytest.approx(SIGMA, rel=0.04)
    # The first differences keep the roll: √(1 + 0.31² / (2 · 2 · 0.2²)) = 1.32 times the noise.
    assert high_frequency_noise(noisy, ["roll"], 0.0, 400.0)["roll"] > 1.25 * SIGMA


def test_robust_spread_ignores_shocks(noisy):
    assert high_frequency_noise(noisy, ["shocks"], 0.0, 400.0)["shocks"] == pytest.approx(SIGMA, rel=0.04)
    # The standard deviation takes them in: √(1 + 20 · 2 · 50² / (20 000 · 2)) = 1.87 times.
    assert high_frequency_noise(noisy, ["shocks"], 0.0, 400.0, robust=False)["shocks"] > 1.7 * SIGMA


def test_noise_counts_only_the_window(noisy):
    frame = noisy.copy()
    frame.loc[frame.t_s > 200.0, "drift"] += 10.0 * SIGMA * np.random.default_rng(4).standard_normal(10_000 - 1)
    # half the samples: a sampling error of 1.3 %
    assert high_frequency_noise(frame, ["drift"], 0.0, 200.0)["drift"] == pytest.approx(SIGMA, rel=0.06)
    assert high_frequency_noise(frame, ["drift"], 250.0, 400.0)["drift"] > 9.0 * SIGMA
    with pytest.raises(ValueError, match="samples"):
        high_frequency_noise(frame, ["drift"], 10.0, 10.05)


def _synthetic_log(scale, seed):
    """Streams at the real rates over 200 s: constants plus white noise of 0.01 × channel index (1, 2,
    ...) × ``scale``, and 3 times that after 100 s."""
    rng = np.random.default_rng(seed)
    log = {}
    for stream, (_, header) in LOG_FILES.items():
        t = np.arange(int(200.0 / PERIODS_S[stream])) * PERIODS_S[stream]
        gain = np.where(t > 100.0, 3.0, 1.0) * scale
        log[stream] = pd.DataFrame({"t_s": t, **{c: 100.0 + 0.01 * (i + 1) * gain * rng.standard_normal(t.size)
                                                 for i, c in enumerate(header[2:])}})  # fmt: skip
    return log


def test_noise_comparison():
    # Simulated noise twice the real one in both windows; the later window 3 times the earlier. Each
    # estimate has 2 500 (GNSS) to 6 600 samples: ≤ 2.5 % per noise (1.17/√n, times 1.08 for the
    # differences' correlation, measured above), ≤ 3.6 % on a ratio; 15 % is > 4σ.
    windows = {"early": (0.0, 99.0), "late": (101.0, 200.0)}
    table = noise_comparison(_synthetic_log(2.0, 1), _synthetic_log(1.0, 2), windows)
    assert list(table.columns) == ["window", "channel", "label", "simulated", "real", "ratio"]
    assert len(table) == 2 * len(CHANNELS) and list(table.channel[: len(CHANNELS)]) == list(CHANNELS)
    np.testing.assert_allclose(table.ratio, 2.0, rtol=0.15)
    np.testing.assert_allclose(table.ratio, table.simulated / table.real, rtol=1e-15)
    late, early = (table[table.window == w].set_index("channel") for w in ("late", "early"))
    np.testing.assert_allclose(late.real / early.real, 3.0, rtol=0.15)
    index = {c: LOG_FILES[stream][1].index(c) - 1 for c, (stream, _) in CHANNELS.items()}  # 1, 2, ... in each file
    np.testing.assert_allclose(early.real, [0.01 * index[c] for c in early.index], rtol=0.15)


def test_plot_log_comparison(real, tmp_path):
    simulated = {s: f.assign(t_s=f.t_s + 0.5) for s, f in real.items()}  # distinguishable from the real log
    path = tmp_path / "logs.png"
    fig = plot_log_comparison(simulated, real, path)
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert len(fig.axes) == len(CHANNELS) == 13
    for ax, (channel, (stream, label)) in zip(fig.axes, CHANNELS.items()):
        assert ax.get_title() == label and "[" in label
        real_line, sim_line = ax.get_lines()
        np.testing.assert_array_equal(real_line.get_ydata(), real[stream][channel])
        np.testing.assert_array_equal(sim_line.get_xdata(), real[stream].t_s + 0.5)
    # the lowest panel of each column carries the time axis: pressure (row 5), GNSS east and down (row 4)
    labelled = [ax.get_title() for ax in fig.axes if ax.get_xlabel() == "time since liftoff [s]"]
    assert labelled == ["GNSS velocity east [m/s]", "GNSS velocity down [m/s]", "pressure [Pa]"]
    fig = plot_log_comparison(simulated, real, None, channels=["gyro_x_radps", "pressure_pa"])
    assert [ax.get_title() for ax in fig.axes] == ["body rate x [rad/s]", "pressure [Pa]"]
    with pytest.raises(ValueError, match="airspeed"):
        plot_log_comparison(simulated, real, None, channels=["airspeed_mps"])

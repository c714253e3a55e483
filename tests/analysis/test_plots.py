"""Impact plot on a synthetic in-memory run: what is drawn, checked against NumPy on the same points.

The expected ellipses are computed here from their definition (sample mean, sample covariance with
ddof = 1, k² = −2 ln(1 − level) for two degrees of freedom), not with ``confidence_ellipse``, so a
plot drawing the wrong ellipse, the wrong points or the axes swapped fails even if the ellipse
module and the plot agree with each other.
"""

import numpy as np
import pytest
import pandas as pd
from matplotlib.colors import to_rgb
from matplotlib.figure import Figure
from matplotlib.image import imread

from rocketmc.analysis import Run, plot_impacts

from ..conftest import CAMPAIGNS, REPO

N = 500
N_FAILED = 7  # status 1; the first 5 of them also have a NaN impact
LEVELS = (0.5, 0.95, 0.99)
COLORS = ("tab:green", "tab:orange", "tab:red")  # plots._ELLIPSE_COLORS, level by level


def _run(n=N, n_failed=N_FAILED):
    rng = np.random.default_rng(11)
    north = rng.normal(900.0, 250.0, n)
    east = rng.normal(300.0, 100.0, n) + 0.2 * north
    status = np.zeros(n, dtype=np.int32)
    status[:n_failed] = 1
    north[: min(5, n_failed)] = np.nan  # failed realizations: not plotted
    outputs = pd.DataFrame({"impact_north_m": north, "impact_east_m": east, "status": status})
    return Run(
        outputs=outputs,
        inputs=pd.DataFrame(index=outputs.index),
        attrs={"campaign_name": "plot-test", "seed": 1},
        units={"impact_north_m": "m", "impact_east_m": "m", "status": "1"},
        status_codes={0: "ok", 1: "non-finite state"},
    )


def _ok_points(run):
    ok = run.outputs["status"].to_numpy() == 0
    return run.outputs["impact_north_m"].to_numpy()[ok], run.outputs["impact_east_m"].to_numpy()[ok]


def _ellipse_lines(ax):
    return [line for line in ax.lines if "ellipse" in line.get_label()]


def test_title_labels_and_points():
    run = _run()
    ax = plot_impacts(run).axes[0]
    title = (f"plot-test: impact points, {N - N_FAILED} ok / {N}, seed 1\n{N_FAILED} failed (not in the ellipses), "
             f"{min(5, N_FAILED)} of them without an impact point")  # fmt: skip
    assert ax.get_title() == title
    assert ax.get_xlabel() == "east of pad [m]" and ax.get_ylabel() == "north of pad [m]"
    north, east = _ok_points(run)
    scatter, failed = ax.collections  # the failed flights that landed drawn apart
    assert np.asarray(failed.get_offsets()).shape == (N_FAILED - 5, 2) and "status 1" in failed.get_label()
    offsets = np.asarray(scatter.get_offsets())
    assert offsets.shape == (N - N_FAILED, 2)  # every ok point once, no failed one
    np.testing.assert_array_equal(offsets, np.column_stack([east, north]))  # east on x, north on y
    (pad,) = [line for line in ax.lines if line.get_label() == "pad"]
    assert (pad.get_xdata()[0], pad.get_ydata()[0]) == (0.0, 0.0)
    (mean,) = [line for line in ax.lines if line.get_label() == "mean impact"]
    np.testing.assert_allclose([mean.get_xdata()[0], mean.get_ydata()[0]], [east.mean(), north.mean()], rtol=1e-12)
    assert ax.get_aspect() == 1.0  # equal aspect: the ellipses are not distorted
    legend = [t.get_text() for t in ax.get_legend().get_texts()]
    assert legend[0] == f"ok impacts ({N - N_FAILED})" and legend[1].startswith("status 1 (2 landed)")
    assert legend[2] == "pad" and legend[-1] == "mean impact"


def test_ellipses_have_the_sample_centre_and_semi_axes():
    """Each drawn outline lies on (x − μ)ᵀ Σ⁻¹ (x − μ) = k² of the ok points (rtol 1e-9: the outline
    is computed in double precision from the same mean and covariance), is closed, and its extent
    along east and north is μ ± sqrt(k² Σ_ii) (rtol 2e-4: 200 outline points, the extreme lying
    between two of them, cos(π/199) ≈ 1 − 1.2e-4). The label's area is π k² sqrt(det Σ)."""
    run = _run()
    ax = plot_impacts(run).axes[0]
    north, east = _ok_points(run)
    mu = np.array([east.mean(), north.mean()])
    sigma = np.cov(np.stack([east, north]), ddof=1)
    lines = _ellipse_lines(ax)
    assert len(lines) == len(LEVELS)
    for line, level, color in zip(lines, LEVELS, COLORS):
        k2 = -2.0 * np.log(1.0 - level)
        xy = np.column_stack([line.get_xdata(), line.get_ydata()]) - mu
        np.testing.assert_allclose(np.einsum("ni,ij,nj->n", xy, np.linalg.inv(sigma), xy), k2, rtol=1e-9)
        np.testing.assert_allclose(xy[0], xy[-1], rtol=0, atol=1e-9)  # closed (sin 2π is ~1e-16, not 0)
        half_widths = np.sqrt(k2 * np.diag(sigma))
        np.testing.assert_allclose(xy.max(axis=0), half_widths, rtol=2e-4)
        np.testing.assert_allclose(-xy.min(axis=0), half_widths, rtol=2e-4)
        area_km2 = np.pi * k2 * np.sqrt(np.linalg.det(sigma)) / 1e6
        inside = np.mean(np.einsum("ni,ij,nj->n", np.column_stack(_ok_points(run)[::-1]) - mu, np.linalg.inv(sigma),
                                   np.column_stack(_ok_points(run)[::-1]) - mu) <= k2)  # fmt: skip
        assert line.get_label() == f"{100 * level:g} % ellipse, {100 * inside:.1f} % inside ({area_km2:.3g} km²)"
        assert to_rgb(line.get_color()) == to_rgb(color)


def test_all_ok_and_too_few_points():
    """No failure line in the title when every flight is ok; with fewer than 3 ok points no ellipse
    and no mean marker (a covariance needs 3), the points still drawn."""
    ax = plot_impacts(_run(n_failed=0)).axes[0]
    assert ax.get_title() == f"plot-test: impact points, {N} ok / {N}, seed 1"
    assert len(_ellipse_lines(ax)) == 3
    ax = plot_impacts(_run(n=10, n_failed=8)).axes[0]
    assert ax.get_title().startswith("plot-test: impact points, 2 ok / 10, seed 1\n8 failed")
    assert np.asarray(ax.collections[0].get_offsets()).shape == (2, 2)
    assert _ellipse_lines(ax) == [] and "mean impact" not in [line.get_label() for line in ax.lines]


def test_png_holds_the_drawing(tmp_path):
    """The file is the figure at 150 dpi (7.5 in square: 1125 px) and shows the three ellipses in
    their colours, the blue points and no fourth ellipse colour. Colour matches within 0.02 per
    channel (the PNG is 8-bit); 'present' means at least 100 pixels (a 1.8-pt outline around an
    ellipse spans thousands)."""
    path = tmp_path / "impacts.png"
    fig = plot_impacts(_run(), path=path)
    assert isinstance(fig, Figure)
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    rgb = imread(path)[..., :3]
    assert rgb.shape == (1125, 1125, 3)

    def pixels(color, tol=0.02):
        return int(np.all(np.abs(rgb - np.array(to_rgb(color))) < tol, axis=-1).sum())

    for color in COLORS:
        assert pixels(color) > 100, color
    assert pixels("tab:purple") == 0  # plots._ELLIPSE_COLORS[3]: only three levels drawn
    blue = (rgb[..., 2] > rgb[..., 0] + 0.2) & (rgb[..., 2] > rgb[..., 1] + 0.1)  # tab:blue points, alpha-blended
    assert blue.sum() > 1000


def test_draws_on_given_axes():
    fig = Figure()
    ax = fig.add_subplot()
    assert plot_impacts(_run(), ax=ax, levels=(0.9,)) is fig
    assert fig.axes == [ax]
    ellipses = _ellipse_lines(ax)
    assert len(ellipses) == 1 and ellipses[0].get_label().startswith("90 % ellipse")
    assert to_rgb(ellipses[0].get_color()) == to_rgb(COLORS[0])


def test_histograms_are_written_and_count_the_flights_shown(tmp_path):
    """The three PNGs are written; the ok bars count the ok flights with the value, the grey ones the failed
    flights that landed (the synthetic file's status-2 row), in the same bins, N in the title."""
    from rocketmc.analysis import load_run
    from rocketmc.analysis.plots import plot_histograms

    from .test_results import _synthetic, _write

    outputs, inputs = _synthetic()
    _write(tmp_path / "run.h5", outputs, inputs)
    figures = plot_histograms(load_run(tmp_path / "run.h5"), tmp_path)
    assert [p.name for p in figures] == ["apogee.png", "impact_distance.png", "landing_speed.png"]
    status = outputs["status"]
    distance = np.hypot(outputs["impact_north_m"], outputs["impact_east_m"])
    for (path, fig), x, unit in zip(figures.items(), (outputs["apogee_agl_m"], distance, outputs["impact_speed_mps"]),
                                    ("[m]", "[m]", "[m/s]")):  # fmt: skip
        assert imread(path).shape[2] in (3, 4)
        ax = fig.axes[0]
        ok_bars, failed_bars = ax.containers
        heights = [np.array([b.get_height() for b in bars]) for bars in (ok_bars, failed_bars)]
        n_ok, n_failed = int((np.isfinite(x) & (status == 0)).sum()), int((np.isfinite(x) & (status == 2)).sum())
        assert (heights[0].sum(), heights[1].sum()) == (n_ok, n_failed) and n_failed == 1
        assert f"N = {n_ok + n_failed} of {len(status)} flights" in ax.get_title() and ax.get_xlabel().endswith(unit)


def _with_setup(run, wind, inputs, azimuth_deg=130.0):
    """``run`` with a ``setup`` attribute holding ``wind`` and the launch azimuth [deg], and ``inputs``."""
    import json

    setup = {"config": {"launch": {"azimuth_deg": azimuth_deg}, "environment": {"wind": wind}}}
    return Run(run.outputs, pd.DataFrame(inputs, index=run.outputs.index), {**run.attrs, "setup": json.dumps(setup)},
               run.units, run.status_codes)  # fmt: skip


def test_launch_and_wind_of_fixed_directions_and_the_arrows_drawn():
    """Two layers from 90° (east), the lower one's speed dispersed: the vector mean blows west at the mean
    speed; the rail azimuth is the circular mean of the drawn ones (359° and 3°: 1°, not 181°)."""
    from rocketmc.analysis.plots import launch_and_wind

    run = _run()
    speed = np.linspace(2.0, 6.0, N)  # mean 4 m/s
    wind = {"model": "layers", "layers": [{"speed_mps": 0.0, "from_deg": 90.0}, {"speed_mps": 10.0, "from_deg": 90.0}]}
    run = _with_setup(run, wind, {"environment.wind.layers.0.speed_mps": speed,
                                  "launch.azimuth_deg": np.where(np.arange(N) % 2, 359.0, 3.0)})  # fmt: skip
    found = launch_and_wind(run)
    assert found["azimuth_deg"] == pytest.approx(1.0, abs=1e-9)
    w = found["wind"]
    assert w["speed_mps"] == pytest.approx(7.0) and w["east_mps"] == pytest.approx(-7.0) and abs(w["north_mps"]) < 1e-12
    assert w["from_deg"] == pytest.approx(90.0) and w["resultant"] == pytest.approx(1.0) and not w["spread"]
    ax = plot_impacts(run).axes[0]
    arrows = [a for a in ax.texts if getattr(a, "arrow_patch", None) is not None]
    assert len(arrows) == 2
    rail, blow = (np.asarray(a.xy) for a in arrows)  # (east, north) of each tip
    assert np.degrees(np.arctan2(*rail)) == pytest.approx(1.0) and np.degrees(np.arctan2(*blow)) == pytest.approx(-90.0)
    legend = [t.get_text() for t in ax.get_legend().get_texts()]
    assert "wind: 2-layer wind\nmean wind 7.0 m/s from 90°\n(the arrow: where it blows to)" in legend


def test_spread_wind_directions_give_no_wind_arrow():
    """Directions drawn uniformly over 360° (as lynx_nominal; here a constant wind): the vector mean is near zero, so
    the figure gives the mean speed, says the direction is spread and draws the rail arrow only; without setup, none."""
    from rocketmc.analysis.plots import launch_and_wind

    rng = np.random.default_rng(5)
    wind = {"model": "constant", "speed_mps": 0.0, "from_deg": 0.0}
    run = _with_setup(_run(), wind, {"environment.wind.speed_mps": rng.uniform(0.0, 8.0, N),
                                     "environment.wind.from_deg": rng.uniform(0.0, 360.0, N)})  # fmt: skip
    w = launch_and_wind(run)["wind"]
    assert w["spread"] and w["resultant"] < 0.15  # ~ 1/sqrt(N) for N = 500
    speed = run.inputs["environment.wind.speed_mps"].mean()
    assert w["speed_mps"] == pytest.approx(speed)
    ax = plot_impacts(run).axes[0]
    assert len([a for a in ax.texts if getattr(a, "arrow_patch", None) is not None]) == 1  # the rail only
    assert any(t.get_text().startswith(f"wind: constant wind\nmean wind speed {speed:.1f} m/s, its direction\nspread")
               for t in ax.get_legend().get_texts())  # fmt: skip
    assert launch_and_wind(_run()) is None  # a file without setup: nothing drawn


def _with_campaign(run, name, inputs, apogee_m=3000.0):
    """``run`` as flown from ``campaigns/<name>.toml`` (its resolved set-up, file digests and all), with ``inputs``
    and every flight's apogee ``apogee_m`` [m]."""
    import json

    from rocketmc.campaign import load_campaign
    from rocketmc.campaign.fingerprint import setup

    outputs = run.outputs.assign(apogee_agl_m=apogee_m)
    return Run(outputs, pd.DataFrame(inputs, index=outputs.index),
               {**run.attrs, "setup": json.dumps(setup(load_campaign(CAMPAIGNS / f"{name}.toml")))}, run.units,
               run.status_codes)  # fmt: skip


def _weather_wind(name, heights_m):
    """(north, east) [m/s] of the day's wind of data/weather/``name`` at EuRoC's site, ``heights_m`` above the pad,
    the components interpolated between its levels (as the flights' ``WindProfile``)."""
    from datetime import datetime, timezone

    from rocketmc.env.weather import geometric_altitude, read_weather

    time = datetime(2023, 10, 13, 12, tzinfo=timezone.utc) if name.endswith(".nc") else None
    w = read_weather(REPO / "src" / "rocketmc" / "data" / "weather" / name, 39.3903, -8.2892, time)
    altitude = geometric_altitude(w.geopotential_height_m) - 160.0
    return (np.interp(heights_m, altitude, -w.speed_mps * np.cos(w.from_rad)),
            np.interp(heights_m, altitude, -w.speed_mps * np.sin(w.from_rad)))  # fmt: skip


@pytest.mark.parametrize("campaign, file, source", [
    ("lynx_euroc_era5", "euroc_2023_all_windows.nc", "ERA5/GFS profile of 2023-10-13 12:00Z (euroc_2023_all_windows.nc)"),
    ("lynx_euroc_sounding", "euroc_2023-10-13_12z_era5_uwyo.txt", "sounding (euroc_2023-10-13_12z_era5_uwyo.txt)"),
])  # fmt: skip
def test_the_days_wind_is_described_and_drawn_not_calm(campaign, file, source):
    """An ERA5 or sounding campaign (its [environment.wind] the schema's calm default): the label names the profile
    and gives its 10 m wind; the mean wind over the heights from the pad to the apogee, turned and scaled per
    flight as drawn, is the arrow. Every flight turned by 30° and scaled by 2: the mean turns by 30° and doubles,
    the 10 m wind (nominal) stays."""
    from rocketmc.analysis.plots import PROFILE_HEIGHTS, launch_and_wind

    north, east = _weather_wind(file, np.linspace(0.0, 3000.0, PROFILE_HEIGHTS))
    speed = np.hypot(north, east)
    north_10, east_10 = _weather_wind(file, 10.0)
    surface = (np.hypot(north_10, east_10), np.degrees(np.arctan2(-east_10, -north_10)) % 360.0)
    base = _with_campaign(_run(), campaign, {})
    turned = _with_campaign(_run(), campaign, {"environment.atmosphere.wind_rotation_deg": np.full(N, 30.0),
                                               "environment.atmosphere.wind_scale": np.full(N, 2.0)})  # fmt: skip
    found, found_turned = launch_and_wind(base), launch_and_wind(turned)
    w, w_turned = found["wind"], found_turned["wind"]
    assert found["source"] == source
    assert w["speed_mps"] == pytest.approx(speed.mean(), rel=1e-12) and w["speed_mps"] > 5.0
    assert (w["north_mps"], w["east_mps"]) == pytest.approx((north.mean(), east.mean()), rel=1e-12)
    assert w["surface"] == pytest.approx(surface, rel=1e-12) and w_turned["surface"] == w["surface"]
    assert w_turned["speed_mps"] == pytest.approx(2.0 * w["speed_mps"], rel=1e-12)
    assert (w_turned["from_deg"] - w["from_deg"]) % 360.0 == pytest.approx(30.0, rel=1e-9)
    legend = [t.get_text() for t in plot_impacts(turned).axes[0].get_legend().get_texts()]
    (note,) = [text for text in legend if text.startswith("wind: ")]
    assert note == (f"wind: {source}:\n{surface[0]:.1f} m/s from {surface[1]:.0f}° at 10 m\n"
                    f"mean wind to apogee {w_turned['speed_mps']:.1f} m/s from {w_turned['from_deg']:.0f}°\n"
                    "(the arrow: where it blows to)")  # fmt: skip
    assert "calm" not in note


def test_a_measured_profile_and_a_profile_not_at_hand():
    """The Roccaraso campaign's measured profile (data/wind, its speed scale dispersed): named, with the range of
    the scales drawn; the same run whose set-up names another file's digest (a user's file, not here): named, not
    drawn."""
    import json

    from rocketmc.analysis.plots import launch_and_wind

    run = _with_campaign(_run(), "lynx_roccaraso_2021", {"environment.wind.speed_scale": np.linspace(0.5, 1.5, N)})
    found = launch_and_wind(run)
    assert found["source"] == "measured profile (roccaraso_2021.csv)" and found["wind"]["scaled"] == (0.5, 1.5)
    legend = [t.get_text() for t in plot_impacts(run).axes[0].get_legend().get_texts()]
    assert any(text.startswith("wind: measured profile (roccaraso_2021.csv):\n") and
               f"\nscaled ×0.50…1.50 over the {N} flights\n" in text for text in legend)  # fmt: skip
    setup = json.loads(run.attrs["setup"])
    setup["files"]["environment.wind.file"] = "0" * 64
    other = Run(run.outputs, run.inputs, {**run.attrs, "setup": json.dumps(setup)}, run.units, run.status_codes)
    assert launch_and_wind(other)["wind"] is None
    legend = [t.get_text() for t in plot_impacts(other).axes[0].get_legend().get_texts()]
    assert "wind: measured profile (roccaraso_2021.csv),\nits file not at hand here: not drawn" in legend

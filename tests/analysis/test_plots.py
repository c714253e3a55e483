"""Impact plot on a synthetic in-memory run."""

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from rocketmc.analysis import Run, confidence_ellipse, plot_impacts

N = 500


def _run():
    rng = np.random.default_rng(11)
    north = rng.normal(900.0, 250.0, N)
    east = rng.normal(300.0, 100.0, N) + 0.2 * north
    status = np.zeros(N, dtype=np.int32)
    status[:7] = 1
    north[:5] = np.nan  # failed realizations: not plotted
    outputs = pd.DataFrame({"impact_north_m": north, "impact_east_m": east, "status": status})
    return Run(
        outputs=outputs,
        inputs=pd.DataFrame(index=outputs.index),
        attrs={"campaign_name": "plot-test", "seed": 1},
        units={"impact_north_m": "m", "impact_east_m": "m", "status": "1"},
        status_codes={0: "ok", 1: "non-finite state"},
    )


def test_writes_png(tmp_path):
    path = tmp_path / "impacts.png"
    fig = plot_impacts(_run(), path=path)
    assert isinstance(fig, Figure)
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 10_000


def test_content_matches_ellipses():
    run = _run()
    fig = plot_impacts(run)
    ax = fig.axes[0]
    assert "plot-test" in ax.get_title() and f"{N - 7} ok / {N}" in ax.get_title()
    assert "7 failed" in ax.get_title()

    ok = run.outputs["status"].to_numpy() == 0
    north = run.outputs["impact_north_m"].to_numpy()[ok]
    east = run.outputs["impact_east_m"].to_numpy()[ok]
    (scatter,) = ax.collections
    np.testing.assert_array_equal(scatter.get_offsets(), np.column_stack([east, north]))

    labels = [line.get_label() for line in ax.lines]
    assert "pad" in labels and "mean impact" in labels
    (line95,) = [line for line in ax.lines if line.get_label().startswith("95 %")]
    b_north, b_east = confidence_ellipse(north, east, 0.95).boundary()
    np.testing.assert_array_equal(line95.get_xdata(), b_east)  # east on x
    np.testing.assert_array_equal(line95.get_ydata(), b_north)  # north on y
    assert sum(label.endswith("km²)") for label in labels) == 3  # 50/95/99 % with area


def test_draws_on_given_axes():
    fig = Figure()
    ax = fig.add_subplot()
    assert plot_impacts(_run(), ax=ax, levels=(0.9,)) is fig
    ellipses = [line.get_label() for line in ax.lines if "ellipse" in line.get_label()]
    assert len(ellipses) == 1 and ellipses[0].startswith("90 % ellipse")

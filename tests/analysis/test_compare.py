"""`rocketmc compare`: landing dispersions and area ratios of result files written by ``ResultWriter``
(the run's own writer, attributes and all) from synthetic impact points, checked against the areas
computed directly with ``ellipse_area_m2`` and against closed forms (a file against itself, a copy
scaled about its centre)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from matplotlib.colors import to_rgb
from matplotlib.image import imread

from rocketmc.analysis import load_run
from rocketmc.analysis.compare import area_ratio, compare, format_comparison, unpaired_reason
from rocketmc.ellipse import bootstrap_intervals, confidence_ellipse, ellipse_area_m2
from rocketmc.analysis.plots import plot_comparison
from rocketmc.campaign import ResultWriter, load_campaign, with_overrides
from rocketmc.campaign.runner import ChunkResult
from rocketmc.cli import main

from ..conftest import CAMPAIGNS

N = 200


@pytest.fixture(scope="module")
def campaign():
    return load_campaign(CAMPAIGNS / "lynx_ballistic.toml")


@pytest.fixture
def write(campaign, tmp_path):
    """``write(name, north, east, status=None, seed=1, of=campaign)``: a complete result file of those impacts [m]
    from campaign ``of``."""

    def write(name, north, east, status=None, seed=1, of=campaign):
        n = len(north)
        status = np.zeros(n, dtype=np.int32) if status is None else np.asarray(status, dtype=np.int32)
        writer = ResultWriter(tmp_path / name, with_overrides(of, n_realizations=n, seed=seed), n)
        writer.write(ChunkResult(0, {"status": status, "impact_north_m": north, "impact_east_m": east}, {}, 0.0), 0)
        return str(writer.finish())

    return write


def _impacts(seed=0, n=N):
    """Correlated normal impact points (north, east) [m], a footprint like lynx_ballistic's."""
    rng = np.random.default_rng(seed)
    north = rng.normal(900.0, 250.0, n)
    return north, rng.normal(300.0, 100.0, n) + 0.4 * north


def _scaled(north, east, factor=0.1):
    """The points scaled by ``factor`` about their mean: the same footprint, area × factor²."""
    return north.mean() + factor * (north - north.mean()), east.mean() + factor * (east - east.mean())


def test_each_file_has_its_ellipse_and_the_report_intervals(write):
    """Area and centre of each file's 95 % ellipse over its ok flights, against ``ellipse_area_m2`` and
    the mean (rel 1e-12: eigenvalues against a determinant, the same covariance); the intervals are
    report's (``bootstrap_intervals``, same seed: equal) and hold the estimate."""
    north, east = _impacts(0)
    status = np.zeros(N, dtype=np.int32)
    status[[5, 6, 7]] = 1
    north_b, east_b = _impacts(1)
    runs = [(path, load_run(path)) for path in (write("a.h5", north, east, status), write("b.h5", north_b, east_b))]
    result = compare(runs)
    assert result["level"] == 0.95
    for entry, (n, e, ok) in zip(result["runs"], [(north, east, status == 0), (north_b, east_b, np.full(N, True))]):
        assert (entry["campaign_name"], entry["n_realizations"], entry["n_ok"]) == ("lynx_ballistic", N, ok.sum())
        ellipse = entry["ellipse"]
        assert ellipse["level"] == 0.95
        assert ellipse["area_m2"] == pytest.approx(ellipse_area_m2(n[ok], e[ok]), rel=1e-12)
        assert (ellipse["center_north_m"], ellipse["center_east_m"]) == pytest.approx((n[ok].mean(), e[ok].mean()), rel=1e-12)
        assert entry["intervals"] == bootstrap_intervals(n[ok], e[ok])
        for key in ("area_m2", "center_north_m", "center_east_m"):
            low, high = entry["intervals"][key]
            assert low < ellipse[key] < high
    assert [r["file"] for r in result["runs"]] == [path for path, _ in runs]
    assert [(r["file"], r["baseline"]) for r in result["ratios"]] == [(runs[1][0], runs[0][0])]


def test_a_file_against_itself_is_one_exactly(write):
    """Paired, every replicate resamples the same points in both: the ratio and both ends of its
    interval are 1 to the bit, the change 0 %."""
    north, east = _impacts()
    status = np.zeros(N, dtype=np.int32)
    status[:4] = 2
    path = write("a.h5", north, east, status)
    run = load_run(path)
    ratio = compare([(path, run), (path, run)])["ratios"][0]
    assert ratio["paired"] is True and ratio["unpaired_reason"] is None
    assert ratio["n_dropped"] == 4 and ratio["n_used"] == [N - 4, N - 4]
    assert ratio["ratio"] == 1.0 and ratio["interval"] == [1.0, 1.0]
    assert ratio["change_pct"] == 0.0 and ratio["change_pct_interval"] == [0.0, 0.0]


def test_a_copy_scaled_by_a_tenth_has_a_hundredth_of_the_area(write):
    """Scaled by 0.1 about its centre, the footprint has 0.01 of the area: to rel 1e-12 (0.1 is not a
    binary fraction; the rounding of the scaled points, ~1e-16 each, summed over N points). Paired (same
    seed and N), every replicate scales the same way: an interval of zero width (1e-12 relative,
    rounding). Unpaired (another seed), the replicates resample the two files independently: the
    standard deviation of a log area is about 1/sqrt(N), of the log ratio sqrt(2/N) = 0.1, so the 95 %
    interval spans about 0.39 of the ratio; more than 0.25 asserted, and it holds 0.01."""
    north, east = _impacts()
    base = write("a.h5", north, east)
    runs = {name: (path, load_run(path)) for name, path in
            (("a", base), ("paired", write("b.h5", *_scaled(north, east))),
             ("unpaired", write("c.h5", *_scaled(north, east), seed=2)))}  # fmt: skip
    paired, unpaired = compare([runs["a"], runs["paired"], runs["unpaired"]])["ratios"]
    for ratio in (paired, unpaired):
        assert ratio["ratio"] == pytest.approx(0.01, rel=1e-12)
        assert ratio["change_pct"] == pytest.approx(-99.0, rel=1e-12)
    assert paired["paired"] is True and paired["n_dropped"] == 0
    low, high = paired["interval"]
    assert high - low < 1e-12 * 0.01 and low == pytest.approx(0.01, rel=1e-12)
    assert unpaired["paired"] is False and unpaired["n_dropped"] is None and unpaired["n_used"] == [N, N]
    low, high = unpaired["interval"]
    assert low < 0.01 < high and (high - low) / 0.01 > 0.25
    assert unpaired["change_pct_interval"] == pytest.approx([100.0 * (low - 1.0), 100.0 * (high - 1.0)], rel=1e-12)


def test_paired_only_with_the_same_seed_n_and_dispersions(write, campaign, capsys):
    """Unpaired, with the reason, for another seed, another N, a dispersion one run draws and the other does not,
    or one drawn another way; paired with the same ones. Unpaired, the comparison resamples independently (no
    dropped flights) and the table says why."""
    north, east = _impacts()
    same = load_run(write("a.h5", north, east, seed=3))
    no_mass = with_overrides(campaign, values={"dispersions.rocket.dry_mass_kg": None})
    wider = with_overrides(campaign, values={"dispersions.rocket.aero.drag_scale": {"dist": "normal", "std": 0.08}})
    cases = {
        "b.h5": (write("b.h5", north, east, seed=3), None),
        "c.h5": (write("c.h5", north, east, seed=4), "seeds differ (a.h5 3, c.h5 4)"),
        "d.h5": (write("d.h5", north[:-1], east[:-1], seed=3), f"N differ (a.h5 {N}, d.h5 {N - 1})"),
        "e.h5": (write("e.h5", north, east, seed=3, of=no_mass), "a.h5 disperses rocket.dry_mass_kg, which e.h5 does not"),
        "f.h5": (write("f.h5", north, east, seed=3, of=wider), "rocket.aero.drag_scale is dispersed differently "
                 "(dist normal, std 0.05, low 0.8, high 1.2 in a.h5, dist normal, std 0.08 in f.h5)"),
    }  # fmt: skip
    for name, (path, reason) in cases.items():
        assert unpaired_reason(same, load_run(path), ("a.h5", name)) == reason
    assert unpaired_reason(load_run(cases["e.h5"][0]), same, ("e.h5", "a.h5")) == (
        "a.h5 disperses rocket.dry_mass_kg, which e.h5 does not")
    ratio = area_ratio(same, load_run(cases["e.h5"][0]), names=("a.h5", "e.h5"))
    assert ratio["paired"] is False and ratio["n_dropped"] is None
    assert ratio["unpaired_reason"] == cases["e.h5"][1]
    paths = [str(write("a.h5", north, east, seed=3)), cases["e.h5"][0]]
    assert main(["compare", *paths]) == 0
    assert f"{paths[1]}: unpaired, {paths[0]} disperses rocket.dry_mass_kg, which {paths[1]} does not: the runs " \
           "resampled independently" in capsys.readouterr().out


def test_the_dispersions_of_a_section_switched_off_keep_the_pairing(write, campaign):
    """A run with the controller on, its canard servos dispersed and a stuck canard drawn, against the same
    campaign without [gnc] (``--controller off``): the switch is what is compared, every shared draw the same,
    paired. A fault drawn in one run that both fly the section of is not."""
    north, east = _impacts()
    on = with_overrides(campaign, controller=True, values={
        "dispersions.gnc.servo.time_constant_s": {"dist": "normal", "std": 0.005},
        "faults": {"stuck_canard": {"probability": 0.1, "time_s": [1.0, 5.0]}}})  # fmt: skip
    off, on = load_run(write("off.h5", north, east)), load_run(write("on.h5", north, east, of=on))
    assert unpaired_reason(off, on) is None and unpaired_reason(on, off) is None
    no_fault = load_run(write("no_fault.h5", north, east, of=with_overrides(campaign, controller=True)))
    assert unpaired_reason(no_fault, on, ("A", "B")) == (
        "B disperses gnc.servo.time_constant_s, which A does not; B disperses faults.stuck_canard, which A does not")


def test_a_run_is_labelled_with_the_switches_it_was_flown_with(write, campaign, capsys):
    """A run flown with options that override its campaign file (the controller switched on, the other aerodynamic
    model, a value set) says so in ``report``, ``compare`` and the plots' labels: its campaign's name alone would
    call it the file's flights. The file's own run is its name alone."""
    north, east = _impacts()
    plain = write("plain.h5", north, east)
    flown = with_overrides(campaign, controller=True, aero_model="simplified", values={"rocket.dry_mass_kg": 28.0})
    switched = write("switched.h5", north, east, of=flown)
    switches = "aero_model simplified, controller on, rocket.dry_mass_kg = 28.0"
    assert load_run(plain).overrides == {} and load_run(plain).label == "lynx_ballistic"
    assert load_run(switched).label == f"lynx_ballistic ({switches})"
    assert main(["compare", plain, switched]) == 0
    rows = [line.split() for line in capsys.readouterr().out.splitlines()[2:4]]
    assert [row[:2] for row in rows] == [[plain, "lynx_ballistic"], [switched, "lynx_ballistic"]]
    assert " ".join(rows[1][2:9]) == f"({switches})"
    assert main(["report", switched]) == 0
    assert f"Flown with: {switches} (the campaign file's setting overridden)" in capsys.readouterr().out
    assert main(["report", plain]) == 0
    assert "Flown with" not in capsys.readouterr().out


def test_flights_failed_in_either_file_are_dropped_from_both(write):
    """A flight not ok in one file leaves both: its far-away (finite) impact, 50 km off, would change
    the area by orders of magnitude if kept. The ratio is that of the areas over the flights ok in
    both (rel 1e-12: the same formula, different summation order)."""
    north, east = _impacts(0)
    north_b, east_b = _impacts(1)
    status_a, status_b = np.zeros(N, dtype=np.int32), np.zeros(N, dtype=np.int32)
    status_a[[3, 10]] = 1
    status_b[[10, 20, 30]] = 2
    north[[3, 10]] = north_b[[10, 20, 30]] = 5e4
    ratio = area_ratio(load_run(write("a.h5", north, east, status_a)), load_run(write("b.h5", north_b, east_b, status_b)))
    kept = (status_a == 0) & (status_b == 0)
    assert ratio["paired"] is True and ratio["n_dropped"] == 4 and ratio["n_used"] == [N - 4, N - 4]
    expected = ellipse_area_m2(north_b[kept], east_b[kept]) / ellipse_area_m2(north[kept], east[kept])
    assert ratio["ratio"] == pytest.approx(expected, rel=1e-12)
    assert ratio["interval"][0] < expected < ratio["interval"][1]


def test_plot_overlays_each_file_in_its_colour(write):
    """One scatter and one 95 % ellipse per file in the file's colour: the points are the ok impacts
    (east on x), each outline lies on (x − μ)ᵀ Σ⁻¹ (x − μ) = k² of its file's points (rtol 1e-9, double
    precision from the same mean and covariance), labelled with name, file and area."""
    north, east = _impacts(0)
    files = [write("a.h5", north, east), write("b.h5", *_scaled(north, east, 0.5))]
    runs = [(path, load_run(path)) for path in files]
    ax = plot_comparison(runs).axes[0]
    ellipses = [line for line in ax.lines if "ellipse" in line.get_label()]
    assert len(ax.collections) == len(ellipses) == 2
    k2 = -2.0 * np.log(1.0 - 0.95)
    for (path, run), scatter, line, color in zip(runs, ax.collections, ellipses, ("tab:blue", "tab:orange")):
        n, e = run.ok_impacts()
        np.testing.assert_array_equal(np.asarray(scatter.get_offsets()), np.column_stack([e, n]))
        xy = np.column_stack([line.get_xdata() - e.mean(), line.get_ydata() - n.mean()])
        sigma = np.cov(np.stack([e, n]), ddof=1)
        np.testing.assert_allclose(np.einsum("ni,ij,nj->n", xy, np.linalg.inv(sigma), xy), k2, rtol=1e-9)
        area_km2 = confidence_ellipse(n, e).area_m2 / 1e6
        assert line.get_label() == f"lynx_ballistic ({path}): 95 % ellipse ({area_km2:.3g} km²)"
        assert to_rgb(line.get_color()) == to_rgb(color) and to_rgb(scatter.get_facecolor()[0][:3]) == to_rgb(color)
    assert ax.get_aspect() == 1.0
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("east of pad [m]", "north of pad [m]")


def test_cli_json_table_and_plot(write, tmp_path, capsys):
    """Exit 0; the JSON is the ``compare`` dict; the table names the pairing; the PNG is the 7.5 in
    figure at 150 dpi (1125 px square) showing the two files' colours (at least 100 pixels each within
    0.02 per channel, 8-bit PNG: the outlines alone span thousands) and no third one."""
    north, east = _impacts()
    status = np.zeros(N, dtype=np.int32)
    status[:3] = 1
    a, b = write("a.h5", north, east), write("b.h5", *_scaled(north, east, 0.5), status)
    png = tmp_path / "compare.png"
    assert main(["compare", a, b, "--json", "--plot", str(png)]) == 0
    out, err = capsys.readouterr()
    result = json.loads(out)
    assert result == json.loads(json.dumps(compare([(a, load_run(a)), (b, load_run(b))])))
    assert result["ratios"][0]["ratio"] == pytest.approx(0.25, rel=1e-12)  # 0.5² on the 197 ok in both
    assert err == f"wrote {png}\n"
    rgb = imread(png)[..., :3]
    assert rgb.shape == (1125, 1125, 3)

    def pixels(color, tol=0.02):
        return int(np.all(np.abs(rgb - np.array(to_rgb(color))) < tol, axis=-1).sum())

    assert pixels("tab:blue") > 100 and pixels("tab:orange") > 100 and pixels("tab:green") == 0
    assert main(["compare", a, b]) == 0
    text = capsys.readouterr().out
    assert text == format_comparison(result) + "\n"
    assert "paired, 3 dropped (not ok in both)" in text and "-75.0" in text


@pytest.mark.parametrize("case, needle", [
    ("missing", "missing.h5: file not found"),
    ("not a result file", "not an HDF5 file"),
    ("one file", "compare needs at least two result files"),
    ("few ok flights", "few.h5: 9 ok flight(s) with an impact point; comparing needs at least 10"),
    ("few ok in both", "y.h5 against {}/x.h5: 0 flight(s) landed in both runs; comparing needs at least 10"),
    ("baseline on a line", "good.h5 against {}/line.h5: the baseline's impact points span no area"),
])  # fmt: skip
def test_cli_errors_are_one_line(write, tmp_path, capsys, case, needle):
    north, east = _impacts(n=20)
    good = write("good.h5", north, east)
    (tmp_path / "text.h5").write_text("not HDF5\n")
    first_half = np.arange(20) < 10
    files = {
        "missing": [good, str(tmp_path / "missing.h5")],
        "not a result file": [good, str(tmp_path / "text.h5")],
        "one file": [good],
        "few ok flights": [good, write("few.h5", north, east, np.arange(20) < 11)],
        "few ok in both": [write("x.h5", north, east, first_half), write("y.h5", north, east, ~first_half)],
        "baseline on a line": [write("line.h5", north, 2.0 * north), good],
    }[case]
    try:
        code = main(["compare", *files])
    except SystemExit as e:  # argparse's own errors
        code = e.code
    out, err = capsys.readouterr()
    assert code == 2 and out == ""
    assert err.startswith("rocketmc: error: ") and err.count("\n") == 1 and needle.format(tmp_path) in err, err


def test_diverged_navigation_is_counted_and_warned(write, tmp_path, capsys):
    """A run whose flights' navigation diverged: its count in the comparison, a warning line in the table and on
    stderr naming the file; the baseline without the flag has none."""
    from rocketmc.analysis.results import DIVERGED

    north, east = _impacts()
    a = write("a.h5", north, east)
    b = str(tmp_path / "b.h5")
    writer = ResultWriter(b, with_overrides(load_campaign(CAMPAIGNS / "lynx_ballistic.toml"), n_realizations=N, seed=1), N)
    flag = np.zeros(N)
    flag[:5] = 1.0
    outputs = {"status": np.zeros(N, dtype=np.int32), "impact_north_m": north, "impact_east_m": east, DIVERGED: flag}
    writer.write(ChunkResult(0, outputs, {}, 0.0), 0)
    writer.finish()
    result = compare([(a, load_run(a)), (b, load_run(b))])
    assert [r["navigation_diverged"] for r in result["runs"]] == [0, 5]
    (line,) = result["warnings"]
    assert line.startswith(f"{b}: ") and "diverged in 5 of 200 flights" in line
    assert main(["compare", a, b]) == 0
    out, err = capsys.readouterr()
    assert f"Warning: {line}" in out and err == f"rocketmc: warning: {line}\n"

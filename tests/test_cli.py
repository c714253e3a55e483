"""The command line: a small campaign end to end, and bad input (exit code 2, no result file)."""

import argparse
import contextlib
import io
import itertools
import json
import re
from pathlib import Path

import h5py
import numpy as np
import pytest

from rocketmc.analysis.flight_plots import FIGURES as FLY_FIGURES
from rocketmc.cli import main

CAMPAIGNS = Path(__file__).parents[1] / "campaigns"


@pytest.fixture(scope="module")
def small_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("run") / "ballistic.h5"
    # lynx_ballistic has no [gnc]: --controller on flies it with the defaults (the thesis's closed loop)
    args = ["-n", "6", "--seed", "7", "--controller", "on", "--out", str(out)]
    log = io.StringIO()
    with contextlib.redirect_stderr(log):
        assert main(["run", str(CAMPAIGNS / "lynx_ballistic.toml"), *args]) == 0
    out.with_suffix(".log").write_text(log.getvalue())  # its progress output, for test_run_says_its_reference
    return out


def test_run_says_its_reference(small_run):
    """A controlled run says once what it steers to: lynx_ballistic's default [gnc] derives it all from the
    campaign (rail 84° toward 130°)."""
    lines = [line for line in small_run.with_suffix(".log").read_text().splitlines() if "guidance reference" in line]
    assert len(lines) == 1 and lines[0].startswith("guidance reference: climb H ") and lines[0].count("(derived)") == 4
    assert "γ0 84° (derived), heading 130° (derived), roll heading 130° (derived)" in lines[0], lines[0]


def test_run_writes_the_contract(small_run):
    with h5py.File(small_run) as f:
        assert f.attrs["complete"] and f.attrs["n_realizations"] == 6 and f.attrs["seed"] == 7
        assert "lynx_ballistic" in f.attrs["campaign_toml"]
        for name in ("apogee_agl_m", "apogee_time_s", "max_mach", "max_dynamic_pressure_pa", "rail_exit_speed_mps",
                     "impact_north_m", "impact_east_m", "impact_time_s", "impact_speed_mps", "status"):  # fmt: skip
            assert f["outputs"][name].shape == (6,) and "unit" in f["outputs"][name].attrs
        assert np.all(f["outputs/status"][:] == 0)
        assert json.loads(f.attrs["setup"])["config"]["gnc"]["guidance"]["window_start_s"] == 1.0
        active = f["outputs/control_active_time_s"]
        assert active.attrs["unit"] == "s" and np.allclose(active[:], 9.0, atol=0.02)  # the 1-10 s window, ±1 period
        assert np.all(f["outputs/canard_deflection_max_rad"][:] <= np.radians(10.0))
        assert json.loads(f["outputs/status"].attrs["codes"])["0"] == "ok"
        speeds = f["inputs/environment.wind.layers.1.speed_mps"][:]
        assert np.all((speeds >= 0) & (speeds <= 30)) and len(set(speeds)) == 6
    assert not Path(str(small_run) + ".partial").exists()


def test_report_json_and_plot(small_run, tmp_path, capsys):
    png = tmp_path / "impacts.png"
    assert main(["report", str(small_run), "--json", "--plot", str(png)]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["n_ok"] == 6
    level95 = [e for e in summary["impact_ellipses"] if e["level"] == 0.95][0]
    assert level95["area_m2"] > 0
    assert png.stat().st_size > 10_000


def test_report_maps(small_run, tmp_path, capsys):
    kml, geojson = tmp_path / "impacts.kml", tmp_path / "impacts.geojson"
    assert main(["report", str(small_run), "--map", str(kml), "--map", str(geojson)]) == 0
    assert "<kml" in kml.read_text() and json.loads(geojson.read_text())["type"] == "FeatureCollection"
    capsys.readouterr()
    assert main(["report", str(small_run), "--map", str(tmp_path / "impacts.txt")]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and err.startswith("rocketmc: error:") and ".kml or .geojson" in err


def test_bad_arguments_exit_2(tmp_path, capsys):
    with pytest.raises(SystemExit) as info:
        main(["run", str(CAMPAIGNS / "lynx_nominal.toml"), "-n", "0"])
    assert info.value.code == 2
    assert main(["run", str(tmp_path / "missing.toml")]) == 2
    assert main(["report", str(tmp_path / "missing.h5")]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 3 and "argument -n" in lines[0] and all("not found" in line for line in lines[1:]), lines


def test_aero_derivatives(capsys):
    """The simplified model of the Lynx build-up at Mach 0.3: the printed and JSON forms agree, the
    centre of pressure follows from Cmα/CNα, and the rocket is statically stable."""
    assert main(["aero", "derivatives", "lynx", "--mach", "0.3", "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    c = result["coefficients_per_rad"]
    assert c["CNa"] > 0 and c["Cma"] < 0 and c["Cmq"] < 0 and c["Clp"] < 0
    assert c["CN_pitch"] > 0 and c["Cm_pitch"] > 0 and c["Cl_roll"] > 0  # the thesis's signs
    d, x_ref = result["reference_length_m"], result["moment_reference_m"]
    assert result["center_of_pressure_m"] == pytest.approx(x_ref - c["Cma"] * d / c["CNa"], rel=1e-12)
    assert 0 < result["static_margin_calibers"]["liftoff"] < result["static_margin_calibers"]["burnout"]
    assert main(["aero", "derivatives", "lynx", "--mach", "0.3"]) == 0
    text = capsys.readouterr().out
    assert f"{c['CNa']:.3f}" in text and "static margin" in text


def test_aero_derivatives_plot(tmp_path, capsys):
    """--plot: CA0, CNα and the centre of pressure against Mach; the curves hold the printed point (Mach 0.3 is on the
    default grid) and the figure has three panels; a figure type matplotlib cannot write: exit 2, nothing written."""
    from rocketmc.campaign.checks import aero_curves
    from rocketmc.cli import _rocket_campaign

    figure = tmp_path / "aero.png"
    assert main(["aero", "derivatives", "lynx", "--mach", "0.3", "--json", "--plot", str(figure)]) == 0
    printed = json.loads(capsys.readouterr().out)
    assert figure.stat().st_size > 0
    curves = aero_curves(_rocket_campaign("lynx"), 0.0)
    at = next(c for c in curves if abs(c["mach"] - 0.3) < 1e-12)  # the grid's 0.3, to rounding: so are the values
    assert at["coefficients_per_rad"] == pytest.approx(printed["coefficients_per_rad"], rel=1e-12, abs=1e-15)
    assert at["center_of_pressure_m"] == pytest.approx(printed["center_of_pressure_m"], rel=1e-12)
    assert main(["aero", "derivatives", "lynx", "--plot", str(tmp_path / "aero.docx")]) == 2
    assert not (tmp_path / "aero.docx").exists()


def test_gnc_design(tmp_path, capsys):
    """The schedule of a controlled Lynx (linear model, 4 speeds × the 3 default altitudes) as JSON, as a
    table and as a figure; a campaign without [gnc] is one line, exit 2."""
    campaign = tmp_path / "controlled.toml"
    campaign.write_text((CAMPAIGNS / "lynx_nominal.toml").read_text()
                        + '\n[rocket.aero]\nmodel = "linear"\n\n[gnc.control]\nspeeds_mps = [20.0, 100.0, 200.0, 300.0]\n')  # fmt: skip
    png = tmp_path / "gains.png"
    assert main(["gnc", "design", str(campaign), "--json", "--plot", str(png)]) == 0
    summary = json.loads(capsys.readouterr().out)
    grid = set(itertools.product((20.0, 100.0, 200.0, 300.0), (0.0, 1000.0, 2000.0)))
    assert len(summary["points"]) == len(grid) == len({(p["speed_mps"], p["altitude_agl_m"]) for p in summary["points"]})
    assert {(p["speed_mps"], p["altitude_agl_m"]) for p in summary["points"]} == grid
    for p in summary["points"]:
        assert np.shape(p["gain"]) == (3, 11) and 0.0 < p["spectral_radius"] < 1.0 and p["riccati_residual"] < 1e-9
        assert 0.0 < p["flown_spectral_radius"] < 1.0
        assert p["altitude_msl_m"] == p["altitude_agl_m"] + 1416.0 and p["pitch"]["K_up"] == p["gain"][1][6]
    assert summary["burnout"]["mass_kg"] == pytest.approx(18.362) and summary["r_weights"] == [100.0, 100.0, 100.0]
    assert summary["integrator_gain"] == [1.0, 12.0, 12.0]
    # lynx_nominal's rail: 84° toward 130°; no reference set but t0_s: all derived from it.
    reference = summary["reference"]
    assert reference["t0_s"] == {"value": 1.5, "derived": False}
    assert all(reference[name]["derived"] for name in ("apogee_m", "flight_path_angle_deg", "heading_deg", "roll_heading_deg"))
    assert reference["flight_path_angle_deg"]["value"] == 84.0 and reference["apogee_m"]["value"] > 0.0
    assert png.stat().st_size > 10_000
    assert main(["gnc", "design", str(campaign)]) == 0
    table = capsys.readouterr().out.splitlines()
    assert table[3].startswith("  guidance reference: climb H ") and table[3].count("(derived)") == 4
    assert "loop as flown: at most 0.99" in table[4]
    assert "K_up" in table[5] and len(table) == 7 + len(grid)  # 5 lines of inputs, 2 of header, a row a point
    assert main(["gnc", "design", str(CAMPAIGNS / "lynx_ballistic.toml"), "--plot", str(tmp_path / "none.png")]) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and err[0].startswith("rocketmc: error:") and "no [gnc] section" in err[0], err
    assert not (tmp_path / "none.png").exists()


@pytest.mark.slow
def test_until_converged_stops_by_itself(tmp_path, capsys):
    """lynx_ballistic with a 25 % target: the 95 % ellipse area's bootstrap interval is that narrow after a
    few hundred flights (its width goes as ~3.9/sqrt(N)), far below the 2000 allowed; the file keeps the
    N reached, a whole number of chunks, and the log says so."""
    out = tmp_path / "converged.h5"
    args = ["run", str(CAMPAIGNS / "lynx_ballistic.toml"), "-n", "2000", "--chunk-size", "50", "--out", str(out)]
    assert main([*args, "--until-converged", "25"]) == 0
    log = capsys.readouterr().err
    with h5py.File(out) as f:
        n = int(f.attrs["n_realizations"])
        assert f.attrs["complete"] and f["outputs/status"].shape == (n,)
    assert 100 <= n < 2000 and n % 50 == 0
    assert f"converged at N = {n}" in log
    with pytest.raises(SystemExit) as info:
        main([*args, "--until-converged", "0"])
    assert info.value.code == 2


README = Path(__file__).parents[1] / "docs" / "guide.md"
OPTION = re.compile(r"(?<![\w-])--?[a-z][a-z0-9-]*")  # -n, --chunk-size; not the -2021 of roccaraso-2021


def _readme_commands():
    """{subcommand words: (options, {option or positional: choices})} of the guide's "The commands" block."""
    block = README.read_text().split("## The commands", 1)[1].split("```sh", 1)[1].split("```", 1)[0]
    commands = {}
    for text in re.split(r"\n(?=rocketmc )", block.strip()):
        tokens = text.split()[1:]
        words = tuple(itertools.takewhile(lambda w: re.fullmatch(r"[a-z]+", w), tokens))
        listed = re.findall(r"(--[a-z-]+) ([a-z0-9-]+(?:\|[a-z0-9-]+)+)", text)  # --aero-model a|b|c
        choices = {option: set(values.split("|")) for option, values in listed}
        positional = tokens[len(words)]
        if re.fullmatch(r"[a-z0-9-]+(\|[a-z0-9-]+)+", positional):  # roccaraso-2021|euroc-2021, not lynx|CAMPAIGN.toml
            choices[None] = set(positional.split("|"))
        commands[words] = (set(OPTION.findall(text)), choices)
    return commands


def _help(capsys, *words):
    with pytest.raises(SystemExit) as info:
        main([*words, "--help"])
    assert info.value.code == 0
    return capsys.readouterr().out


def test_help_matches_the_readme(capsys):
    """`--help` of the program and of each subcommand against the guide's "The commands" block: the same
    subcommands, and for each the same options (both ways: an option dropped from the parser or one
    added without the README saying so fails) and the same choices where the README lists them."""
    documented = _readme_commands()
    assert set(documented) == {("run",), ("report",), ("compare",), ("aero", "derivatives"), ("gnc", "design"),
                               ("sensors", "simulate"), ("navigate",), ("fly",), ("validate",), ("bench",),
                               ("budget",), ("motors",), ("import",), ("sensitivities",), ("tune",),
                               ("airbrakes", "design")}  # fmt: skip
    listed = re.search(r"\{([a-z,]+)\}", _help(capsys)).group(1).split(",")
    assert sorted(listed) == sorted(words[0] for words in documented)
    assert re.search(r"\{([a-z,]+)\}", _help(capsys, "aero")).group(1).split(",") == ["derivatives"]
    assert re.search(r"\{([a-z,]+)\}", _help(capsys, "gnc")).group(1).split(",") == ["design"]
    assert re.search(r"\{([a-z,]+)\}", _help(capsys, "sensors")).group(1).split(",") == ["simulate"]
    assert re.search(r"\{([a-z,]+)\}", _help(capsys, "airbrakes")).group(1).split(",") == ["design"]
    for words, (options, choices) in documented.items():
        text = _help(capsys, *words)
        assert text.startswith(f"usage: rocketmc {' '.join(words)} "), text
        assert set(OPTION.findall(text)) - {"-h", "--help"} == options, words
        for option, values in choices.items():
            shown = re.search(r"\{([^}]*)\}" if option is None else re.escape(option) + r" \{([^}]*)\}", text)
            assert shown and set(shown.group(1).split(",")) == values, (words, option)


def _subcommands(parser, words=()):
    """(words, parser) of every subcommand, nested ones (aero derivatives) included."""
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield from _subcommands(sub, (*words, name))
    if words and not any(isinstance(a, argparse._SubParsersAction) for a in parser._actions):
        yield words, parser


def test_options_are_spelled_the_same_everywhere():
    """One meaning (argparse's dest) has one spelling in every subcommand and one spelling one
    meaning, except the old spellings kept (cli.OLD_SPELLINGS, each after the current one); a folder option's
    name ends in -dir, and only those take a DIR."""
    from rocketmc.cli import OLD_SPELLINGS, build_parser

    spelling_of, meaning_of = {}, {}
    commands = list(_subcommands(build_parser()))
    assert len(commands) >= 9
    for words, parser in commands:
        for action in parser._actions:
            if not action.option_strings or action.dest == "help":
                continue
            current, *old = action.option_strings
            where = (words, current)
            assert spelling_of.setdefault(action.dest, current) == current, where
            assert meaning_of.setdefault(current, action.dest) == action.dest, where
            assert all(OLD_SPELLINGS.get(o) == current for o in old), where
            assert current.endswith("-dir") == (action.metavar == "DIR"), where
    assert spelling_of["out"] == "--out" and spelling_of["plot_dir"] == "--plot-dir" and spelling_of["n"] == "-n"


@pytest.mark.parametrize("old, new", [
    (["validate", "euroc-2021", "--plot", "x"], ["validate", "euroc-2021", "--plot-dir", "x"]),
    (["navigate", "log", "--plot", "x"], ["navigate", "log", "--plot-dir", "x"]),
    (["sensors", "simulate", "c.toml", "--out", "x"], ["sensors", "simulate", "c.toml", "--out-dir", "x"]),
    (["bench", "--n", "10", "20", "--models", "linear"], ["bench", "-n", "10", "20", "--aero-model", "linear"]),
])  # fmt: skip
def test_old_spellings_still_parse_as_the_new(old, new):
    from rocketmc.cli import build_parser

    assert vars(build_parser().parse_args(old)) == vars(build_parser().parse_args(new))


def test_fly(tmp_path, capsys):
    """One realization's time series as HDF5 with units, its figures and KML path; the summary is the flight's."""
    out, kml, figures = tmp_path / "flight.h5", tmp_path / "path.kml", tmp_path / "figures"
    args = ["--realization", "2", "--out", str(out), "--kml", str(kml), "--plot-dir", str(figures), "--quiet"]
    assert main(["fly", str(CAMPAIGNS / "lynx_ballistic.toml"), *args]) == 0
    printed = capsys.readouterr().out
    assert printed.startswith("lynx_ballistic, realization 2: ok") and "apogee" in printed and "impact" in printed
    with h5py.File(out) as f:
        assert f.attrs["realization"] == 2 and f.attrs["status"] == 0
        assert f["series/altitude"].attrs["unit"] == "m" and f["series/static_margin"].attrs["unit"] == "cal"
        apogee = f["summary/apogee_agl_m"][()]
        assert f"{apogee:.1f} m above the pad" in printed
        assert 0.0 <= apogee - f["series/altitude"][:].max() < 1e-3  # the highest sample within h/2 of apogee
        assert f["series/time"].shape == f["series/phase"].shape and f["series/phase"][-1] == b"landed"
    assert "<LineString>" in kml.read_text() and "apogee" in kml.read_text()
    assert sorted(p.name for p in figures.iterdir()) == sorted(FLY_FIGURES)


def test_fly_bad_input_exit_2(tmp_path, capsys):
    campaign = str(CAMPAIGNS / "lynx_ballistic.toml")
    assert main(["fly", campaign, "--realization", "1000"]) == 2
    assert main(["fly", campaign, "--out", str(tmp_path / "flight.txt")]) == 2
    assert main(["fly", campaign, "--kml", str(tmp_path / "path.geojson")]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 3 and all(line.startswith("rocketmc: error:") for line in lines), lines
    assert "--realization 1000" in lines[0] and "(0 to 999)" in lines[0]
    assert "--out" in lines[1] and ".csv or .h5" in lines[1] and "--kml" in lines[2]
    assert not list(tmp_path.iterdir())


def test_budget_bad_input_exit_2(tmp_path, capsys):
    """`budget` refuses, in one line and before any flight or file, a campaign without [gnc], one on perfect
    navigation, too few realizations for an ellipse, an unknown source and a figure it cannot write."""
    gnc = str(CAMPAIGNS / "lynx_ballistic_gnc_1s.toml")
    assert main(["budget", str(CAMPAIGNS / "lynx_ballistic.toml"), "--plot", str(tmp_path / "b.png")]) == 2
    assert main(["budget", str(CAMPAIGNS / "lynx_ballistic_ctrl_1s.toml"), "--plot", str(tmp_path / "b.png")]) == 2
    assert main(["budget", gnc, "-n", "9", "--plot", str(tmp_path / "b.png")]) == 2
    assert main(["budget", gnc, "-n", "16", "--sources", "gyroscope,compass"]) == 2
    assert main(["budget", gnc, "-n", "16", "--plot", str(tmp_path / "budget.txt")]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 5 and all(line.startswith("rocketmc: error:") for line in lines), lines
    assert "lynx_ballistic.toml: no [gnc] section" in lines[0]
    assert "gnc.navigation is 'truth'" in lines[1]
    assert "9 realizations: the ellipses need at least 10" in lines[2]
    assert "unknown source(s) compass" in lines[3] and "gyroscope" in lines[3]
    assert "--plot" in lines[4] and ".png" in lines[4]
    assert not list(tmp_path.iterdir())


def test_report_of_an_unstable_rocket(tmp_path, capsys):
    """Acceptance: campaigns/unstable_rocket.toml (no fins) tumbles; report shows its impacts,
    counts and statuses: every flight failed with status 3, each with an impact point, drawn apart; run warned
    of the negative static margin before flying (even with --quiet) and the report repeats it from the file."""
    out, png = tmp_path / "unstable.h5", tmp_path / "unstable.png"
    assert main(["run", str(CAMPAIGNS / "unstable_rocket.toml"), "-n", "8", "--out", str(out), "--quiet"]) == 0
    warned = [line for line in capsys.readouterr().err.splitlines() if line.startswith("rocketmc: warning:")]
    assert any("statically unstable at liftoff" in line for line in warned), warned
    assert main(["report", str(out), "--json", "--plot", str(png)]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert any("statically unstable at liftoff" in line for line in summary["warnings"]), summary["warnings"]
    assert summary["n_ok"] == 0 and summary["impact_ellipses"] == []
    assert summary["failed"] == [{"code": 3, "message": summary["failed"][0]["message"], "count": 8, "landed": 8,
                                  "no_impact_point": 0}]  # fmt: skip
    assert png.stat().st_size > 10_000
    assert main(["report", str(out)]) == 0
    text = capsys.readouterr().out
    assert "Failed realizations" in text and "Realizations: 8 total, 0 ok" in text
    assert "Warning: unstable_rocket: the nominal rocket is statically unstable at liftoff" in text


def test_report_outside_radius(small_run, capsys):
    assert main(["report", str(small_run), "--json", "--outside-radius", "1e7"]) == 0
    result = json.loads(capsys.readouterr().out)["outside_radius"]
    assert result["outside"] == 0 and result["n"] == 6 and result["upper_bound_none_outside"] > 0.39
    with pytest.raises(SystemExit) as info:
        main(["report", str(small_run), "--outside-radius", "-5"])
    assert info.value.code == 2 and "--outside-radius" in capsys.readouterr().err


def test_report_csv(small_run, tmp_path, capsys):
    """One row per realization, status first, columns with units; values as in the result file."""
    import pandas as pd

    csv = tmp_path / "run.csv"
    assert main(["report", str(small_run), "--csv", str(csv)]) == 0
    table = pd.read_csv(csv, index_col="realization")
    with h5py.File(small_run) as f:
        assert list(table["status"]) == list(f["outputs/status"][:])
        np.testing.assert_array_equal(table["impact_north_m [m]"], f["outputs/impact_north_m"][:])  # repr round-trips
        np.testing.assert_array_equal(table["input: launch.azimuth_deg"], f["inputs/launch.azimuth_deg"][:])
    assert len(table) == 6
    capsys.readouterr()
    assert main(["report", str(small_run), "--csv", str(tmp_path / "run.txt")]) == 2
    assert "--csv" in capsys.readouterr().err and not (tmp_path / "run.txt").exists()


def test_report_maps_of_failed_flights(tmp_path, capsys):
    """The failed flights that landed are on the maps apart, with their status (a crafted file: no flight)."""
    from .test_cli_errors import write_result

    status = np.zeros(50, np.int32)
    status[:4] = 3
    result = write_result(tmp_path / "run.h5", status=status)
    with h5py.File(result, "r+") as f:
        f["outputs/status"].attrs["codes"] = json.dumps({"0": "ok", "3": "tumbled"})
    geojson, kml = tmp_path / "m.geojson", tmp_path / "m.kml"
    assert main(["report", str(result), "--map", str(geojson), "--map", str(kml)]) == 0
    failed = [x for x in json.loads(geojson.read_text())["features"] if x["properties"].get("status") == 3]
    assert [x["properties"]["index"] for x in failed] == [0, 1, 2, 3]
    assert {x["properties"]["message"] for x in failed} == {"tumbled"}
    with h5py.File(result) as f:
        assert [x["properties"]["apogee_m"] for x in failed] == f["outputs/apogee_agl_m"][:4].tolist()
    assert "status 3 (4 landed): tumbled" in kml.read_text()


def test_report_plots(small_run, tmp_path, capsys):
    """--plot-dir DIR makes the folder and writes the three histograms; a file in its place: one line, exit 2."""
    folder = tmp_path / "histograms"
    assert main(["report", str(small_run), "--plot-dir", str(folder)]) == 0
    assert sorted(p.name for p in folder.iterdir()) == ["apogee.png", "impact_distance.png", "landing_speed.png"]
    capsys.readouterr()
    (tmp_path / "taken").write_text("")
    assert main(["report", str(small_run), "--plot-dir", str(tmp_path / "taken")]) == 2
    err = capsys.readouterr().err
    assert "--plot-dir" in err and len(err.splitlines()) == 1
    assert main(["report", str(small_run), "--plot-dir", str(tmp_path / "no" / "such")]) == 2
    assert not (tmp_path / "no").exists()


def test_report_outside_polygon(small_run, tmp_path, capsys):
    """A square of ±0.5° around the pad holds every flight; a malformed file: one line naming it, exit 2, no output."""
    import tomllib

    with h5py.File(small_run) as f:
        site = tomllib.loads(f.attrs["campaign_toml"])["site"]
    lat, lon = site["latitude_deg"], site["longitude_deg"]
    ring = [[lon - 0.5, lat - 0.5], [lon + 0.5, lat - 0.5], [lon + 0.5, lat + 0.5], [lon - 0.5, lat + 0.5], [lon - 0.5, lat - 0.5]]
    area = tmp_path / "range.geojson"
    area.write_text(json.dumps({"type": "Polygon", "coordinates": [ring]}))
    assert main(["report", str(small_run), "--json", "--outside-polygon", str(area)]) == 0
    result = json.loads(capsys.readouterr().out)["outside_polygon"]
    assert result["outside"] == 0 and result["n"] == 6 and result["polygon"] == "range.geojson"
    bad, csv = tmp_path / "bad.csv", tmp_path / "out.csv"
    bad.write_text("lat_deg,longitude\n41,14\n")
    assert main(["report", str(small_run), "--outside-polygon", str(bad), "--csv", str(csv)]) == 2
    out, err = capsys.readouterr()
    assert out == "" and len(err.splitlines()) == 1 and str(bad) in err and "lon_deg" in err and not csv.exists()


def test_motors_lists_the_library(capsys):
    """The table's header and one line per motor; a search keeps those whose name, designation or maker holds it."""
    assert main(["motors"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].split()[:4] == ["motor", "designation", "maker", "diameter"] and len(lines) == 1 + 61
    assert main(["motors", "L-1350"]) == 0
    (header, row) = capsys.readouterr().out.splitlines()
    assert row.split() == ["Cesaroni_4263L1350-P", "4263-L1350-CS-P", "CTI", "75", "486", "4280", "L", "1350", "3.17",
                           "2.025", "3.571"]  # fmt: skip


def test_motors_without_a_match_exits_2(capsys):
    assert main(["motors", "hybrid"]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err == "rocketmc: error: no motor of the library matches 'hybrid' (`rocketmc motors` lists them all)\n"

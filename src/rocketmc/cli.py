"""The ``rocketmc`` command line: ``run`` a campaign, ``report`` on its result file, ``compare`` the
landing dispersion of result files, ``aero derivatives`` of a rocket, ``gnc design``: the LQI gains of
a campaign, ``sensors simulate``: one realization's sensor log, ``navigate``: the navigation filters replayed on
a sensor log, ``fly``: one flight's time series, ``validate`` the simulation against a real flight, ``bench`` this
machine, ``budget``: the GNC error budget of a closed-loop campaign, ``motors``: the built-in motor library,
``import``: a campaign from an OpenRocket design."""

from __future__ import annotations

import argparse
import functools
import json
import math
import os
import re
import signal
import sys
from pathlib import Path

from .runtime import CORES, __version__
from .env.atmosphere import MAX_ALTITUDE_M
from .errors import RocketmcError


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # one line, exit code 2
        self.exit(2, f"rocketmc: error: {message}\n")


def _run(args) -> int:
    from .campaign.run import run_campaign
    from .campaign.runner import run_chunks

    campaign = _campaign(args.campaign, n_realizations=args.n, seed=args.seed, **_switched(args))
    realizations = _trajectories(args.trajectories)
    progress = _progress(args.quiet)
    options = dict(chunk_size=args.chunk_size, resume=args.resume, force=args.force,
                   until_converged_pct=args.until_converged, trajectories_of=realizations,
                   trajectory_interval_s=args.trajectory_interval, progress=progress, warn=lambda line: _warn([line]))  # fmt: skip
    try:
        if args.scheduler is None and args.workers is None:
            run_campaign(campaign, args.out, executor=run_chunks, **options)
            return 0
        try:
            from .campaign import distributed as dask
        except ModuleNotFoundError as e:
            if e.name not in ("dask", "distributed"):
                raise
            raise RocketmcError("--workers/--scheduler need the optional 'dask' extra (pip install 'rocketmc[dask]')") from None
        with dask.cluster(args.scheduler, args.workers) as client:
            progress(dask.describe(client))
            run_campaign(campaign, args.out, executor=functools.partial(dask.run_chunks, client), **options)
        return 0
    finally:
        progress.end()


class _progress:
    """Progress lines on stderr (none with --quiet); on a terminal, transient lines overwrite each other in place."""

    def __init__(self, quiet: bool):
        self.quiet, self.tty, self.open = quiet, sys.stderr.isatty() and not quiet, False

    def __call__(self, line: str, transient: bool = False) -> None:
        if not self.quiet:
            self.open = transient and self.tty
            print(("\r\033[K" if self.tty else "") + line, end="" if self.open else "\n", file=sys.stderr, flush=True)

    def end(self) -> None:
        """Keep the last transient line."""
        if self.open:
            print(file=sys.stderr)
            self.open = False


def _trajectories(text: str | None) -> list[int]:
    """The realizations of ``run --trajectories I,J,...`` (none: not given); a one-line RocketmcError for a malformed
    list (the campaign checks the rest, ``run_campaign``)."""
    if text is None:
        return []
    if not re.fullmatch(r"\d+(,\d+)*", text):
        raise RocketmcError(f"--trajectories {text}: expected realization indices separated by commas (0,5,17)")
    return [int(word) for word in text.split(",")]


def _warn(lines: list[str]) -> None:
    """Each of ``lines`` as a ``rocketmc: warning:`` line on stderr (shown even with --quiet)."""
    for line in lines:
        print(f"rocketmc: warning: {' '.join(line.split())}", file=sys.stderr)


def _report(args) -> int:
    from .analysis import format_summary, load_run, plot_impacts, summarize
    from .analysis.results import navigation_warnings
    from .analysis.export import MAP_SUFFIXES, write_map

    plot = None if args.plot is None else _output_file("--plot", args.plot, _figure_suffixes())
    maps = [_refuse_existing("--map", _output_file("--map", path, MAP_SUFFIXES), args.force) for path in args.map or []]
    csv = None if args.csv is None else _refuse_existing("--csv", _output_file("--csv", args.csv, (".csv",)), args.force)
    plots = None if args.plot_dir is None else Path(args.plot_dir)
    if plots is not None and (plots.exists() and not plots.is_dir() or not plots.parent.is_dir()):
        raise RocketmcError(f"--plot-dir {plots}: expected a folder, or a new one's name in an existing folder")
    run = load_run(args.file)
    summary = summarize(run)
    _warn(navigation_warnings(run))
    from .analysis.safety import format_outside, outside_polygon, outside_radius, read_polygon

    if args.outside_radius is not None:
        summary["outside_radius"] = outside_radius(run, args.outside_radius)
    if args.outside_polygon is not None:
        from .analysis.export import site_of

        rings = read_polygon(args.outside_polygon, *site_of(run)[1:])
        summary["outside_polygon"] = outside_polygon(run, rings, Path(args.outside_polygon).name)
    text = format_summary(summary)
    for key in ("outside_radius", "outside_polygon"):
        if key in summary:
            text += "\n\n" + format_outside(summary[key])
    print(json.dumps(summary, indent=2, allow_nan=False) if args.json else text)
    if plot:
        plot_impacts(run, path=plot)
        print(f"wrote {plot}", file=sys.stderr)
    for path in maps:
        print(f"wrote {write_map(run, path)}", file=sys.stderr)
    if csv:
        from .analysis.export import write_csv

        print(f"wrote {write_csv(run, csv)}", file=sys.stderr)
    if plots is not None:
        from .analysis.plots import plot_histograms

        plots.mkdir(exist_ok=True)
        for path in plot_histograms(run, plots):
            print(f"wrote {path}", file=sys.stderr)
    return 0


def _compare(args) -> int:
    from .analysis import load_run
    from .analysis.compare import compare, format_comparison
    from .analysis.plots import plot_comparison

    plot = None if args.plot is None else _output_file("--plot", args.plot, _figure_suffixes())
    runs = [(file, load_run(file)) for file in args.files]
    comparison = compare(runs)
    _warn(comparison["warnings"])
    print(json.dumps(comparison, indent=2, allow_nan=False) if args.json else format_comparison(comparison))
    if plot:
        plot_comparison(runs, path=plot)
        print(f"wrote {plot}", file=sys.stderr)
    return 0


SENSITIVITY_CHUNK = 256
"""``sensitivities``' realizations per chunk by default: a 256-flight chunk of lynx_ballistic's derivatives peaked at
3.6 GB (compilation included), where a run's chunk of 1000 flights takes ~1 GB."""


def _sensitivities(args) -> int:
    from .analysis.sensitivities import format_sensitivities, plot_tornado, sensitivity_table
    from .campaign.derivatives import check_inputs, default_inputs
    from .campaign.run import run_campaign
    from .files import file_stem

    plot = None if args.plot is None else _output_file("--plot", args.plot, _figure_suffixes())
    campaign = _campaign(args.campaign, n_realizations=args.n, seed=args.seed, **_switched(args))
    dispersed = default_inputs(campaign)
    named = [] if args.wrt is None else [path.strip() for path in args.wrt.split(",")]
    wrt = dispersed + [path for path in named if path not in dispersed]
    check_inputs(campaign, wrt)
    if not wrt:
        raise RocketmcError(f"{args.campaign}: no continuous dispersion to differentiate with respect to; name design "
                            "numbers with --wrt")  # fmt: skip
    out = args.out or f"{file_stem(campaign.config.name)}_sensitivities.h5"
    progress = _progress(args.quiet)
    progress(f"derivatives with respect to {len(wrt)} inputs ({len(dispersed)} dispersed), reverse mode: a flight's "
             "derivatives and linearity check cost about 20 flights of a run")  # fmt: skip
    try:
        run_campaign(campaign, out, chunk_size=args.chunk_size or SENSITIVITY_CHUNK, resume=args.resume,
                     force=args.force, progress=progress, warn=lambda line: _warn([line]), derivatives_wrt=wrt)  # fmt: skip
    finally:
        progress.end()
    table = sensitivity_table(out)
    print(json.dumps(table, indent=2) if args.json else format_sensitivities(table))
    if plot:
        print(f"wrote {plot_tornado(table, plot)}", file=sys.stderr)
    return 0


def _tune(args) -> int:
    from .campaign import ConfigError
    from .campaign.loader import with_overrides
    from .analysis.plots import plot_tuning
    from .campaign.tuning import TRAINING_SEED_OFFSET, check_parameters, evaluate, rounded, tune, tuned_campaign_text

    plot = None if args.plot is None else _output_file("--plot", args.plot, _figure_suffixes())
    out = _output_file("--out", args.out, (".toml",))
    if out.exists() and not args.force:
        raise RocketmcError(f"--out {out}: exists (--force replaces it)")
    campaign = _campaign(args.campaign, **_switched(args))
    target = args.apogee_target_m
    if args.objective == "apogee_error" and target is None:
        if campaign.config.airbrakes is None:
            raise RocketmcError("--apogee-target-m: needed by --objective apogee_error (no [airbrakes] target to take)")
        target = campaign.config.airbrakes.target_apogee_m
    given = [item.strip().partition("=") for item in args.params.split(",") if item.strip()]
    paths = [path.strip() for path, _, _ in given]
    starts = {path.strip(): _number(f"--params {path.strip()}", start) for path, _, start in given if start}
    if "gnc.guidance.wind_gain" in paths and "gnc.guidance.wind_gain" not in campaign.nominal:
        starts.setdefault("gnc.guidance.wind_gain", 1.0)  # off unless set: from the wind itself moving the reference
    brakes = campaign.config.airbrakes
    if brakes is not None and brakes.reference is None and any(path.startswith("airbrakes.reference.") for path in starts):
        starts = {"airbrakes.reference": {}, **starts}  # the section the defaults were taken from, to set a start in
    try:
        campaign = with_overrides(campaign, values=starts) if starts else campaign
        check_parameters(campaign, paths)
    except ConfigError as e:
        raise RocketmcError(f"{args.campaign}: {e}") from None
    brakes_only = all(path.startswith("airbrakes.") for path in paths)
    progress = _progress(args.quiet)
    try:
        tuning = tune(campaign, paths, args.objective, args.train, args.steps, args.learning_rate,
                      target, args.train_turbulence, progress)  # fmt: skip
        values = rounded(tuning.tuned)
        calm = "" if args.train_turbulence else " without turbulence"
        comment = (f"Tuned by `rocketmc tune` ({args.objective}, {args.train} training flights{calm} of seed "
                   f"{campaign.config.seed + TRAINING_SEED_OFFSET}, {args.steps} Adam steps of {args.learning_rate:g}, "
                   f"the lowest training objective at step {tuning.best}) from {Path(args.campaign).name}.")  # fmt: skip
        out.write_text(tuned_campaign_text(campaign, Path(args.campaign), out, values, comment))
        tuned = _campaign(str(out), **_switched(args))
        held_out = {}
        if args.test:
            off = with_overrides(campaign, airbrakes=False) if brakes_only else with_overrides(campaign, controller=False)
            runs = {"controller off": off, "start": campaign, "tuned": tuned}
            for label, run in runs.items():
                progress(f"held out: {args.test} flights of seed {campaign.config.seed}, {label}")
                held_out[label] = evaluate(run, args.objective, args.test, target)
    finally:
        progress.end()
    result = {"campaign": args.campaign, "objective": args.objective, "train": args.train, "steps": args.steps,
              "best_step": tuning.best, "initial": dict(zip(paths, tuning.values[0].tolist())), "tuned": values,
              "training_objective": tuning.objective.tolist(), "held_out": held_out, "out": str(out)}  # fmt: skip
    print(json.dumps(result, indent=2, allow_nan=False) if args.json else _tuning_text(result))
    if plot:
        print(f"wrote {plot_tuning(tuning, held_out, plot)}", file=sys.stderr)
    return 0


def _number(field: str, text: str) -> float:
    """``text`` as a finite number, else a one-line RocketmcError naming ``field``."""
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        raise RocketmcError(f"{field}: expected a number after '=', got {text!r}")
    return value


def _tuning_text(result: dict) -> str:
    area = result["objective"] == "ellipse_area"
    shown = lambda value: f"{value / 1e6:.3f} km²" if area else f"{value:.1f} m"  # noqa: E731
    history = result["training_objective"]
    lines = [f"{result['objective']} over {result['train']} training flights: {shown(history[0])} at the start, "
             f"{shown(history[result['best_step']])} at step {result['best_step']} of {result['steps']}"]  # fmt: skip
    lines += [f"  {path:36s} {result['initial'][path]:10.4g} -> {value:.4g}" for path, value in result["tuned"].items()]
    if result["held_out"]:
        base = result["held_out"]["controller off"]["value"]
        lines.append("held out (the campaign's own seed):")
        for label, r in result["held_out"].items():
            change = "the baseline" if label == "controller off" else f"{100 * (r['value'] / base - 1):+.1f} % against it"
            lines.append(f"  {label:15s} {shown(r['value']):>12s} ({change}), mean apogee {r['apogee_mean_m']:.0f} m, "
                         f"{r['failed']} failed")  # fmt: skip
    lines.append(f"wrote {result['out']}")
    return "\n".join(lines)


def _figure_suffixes() -> tuple[str, ...]:
    """The file suffixes matplotlib writes figures as (.png, .pdf, .svg, ...)."""
    from matplotlib.figure import Figure

    return tuple(f".{kind}" for kind in Figure().canvas.get_supported_filetypes())


def _output_file(option: str, path: str, suffixes: tuple[str, ...]) -> Path:
    """``path`` given to ``option`` if a file of one of ``suffixes`` can be written there, checked
    before any work; else a one-line RocketmcError."""
    path = Path(path)
    if path.suffix.lower() not in suffixes:
        raise RocketmcError(f"{option} {path}: expected a {' or '.join(suffixes)} file name")
    if path.is_dir():
        raise RocketmcError(f"{option} {path}: is a folder, expected a file name")
    folder = path.parent
    if not folder.is_dir():
        raise RocketmcError(f"{option} {path}: no folder {folder} to write it in")
    if not os.access(folder, os.W_OK) or (path.exists() and not os.access(path, os.W_OK)):
        raise RocketmcError(f"{option} {path}: not writable (read-only folder or file)")
    return path


def _refuse_existing(option: str, path: Path, force: bool) -> Path:
    """``path``, unless a data file is there already and ``force`` is off: then a one-line RocketmcError
    (figures are redrawn in place; data files are replaced only with ``--force``)."""
    if path.exists() and not force:
        raise RocketmcError(f"{option} {path}: the file exists; use --force to replace it")
    return path


def _campaign(path, **overrides):
    """The campaign file ``path`` with the CLI's overrides (N, seed, aerodynamic model, controller); an error
    names the file."""
    from .campaign import ConfigError, load_campaign, with_overrides

    try:
        return with_overrides(load_campaign(path), **overrides)
    except ConfigError as e:
        raise RocketmcError(f"{path}: {e}") from None


def _rocket_campaign(rocket: str):
    """The campaign file ``rocket``, or a minimal campaign around the preset of that name."""
    from .campaign import ConfigError, campaign_from_dict

    if rocket.endswith(".toml"):
        return _campaign(rocket)
    try:
        return campaign_from_dict({
            "name": rocket, "n_realizations": 1, "seed": 0, "rocket": {"preset": rocket},
            "site": {"latitude_deg": 0.0, "longitude_deg": 0.0, "altitude_m": 0.0},
            "launch": {"rail_length_m": 1.0, "elevation_deg": 90.0, "azimuth_deg": 0.0},
        })  # fmt: skip
    except ConfigError as e:
        raise RocketmcError(f"{rocket}: {e}") from None


def _aero_derivatives(args) -> int:
    from .analysis.plots import plot_aero_curves
    from .campaign.checks import aero_curves, aero_derivatives, format_aero_derivatives

    plot = None if args.plot is None else _output_file("--plot", args.plot, _figure_suffixes())
    campaign = _rocket_campaign(args.rocket)
    result = {"rocket": args.rocket, **aero_derivatives(campaign, args.mach, args.altitude)}
    print(json.dumps(result, indent=2) if args.json else format_aero_derivatives(result))
    if plot:
        plot_aero_curves(aero_curves(campaign, args.altitude), campaign.config.name, plot)
        print(f"wrote {plot}", file=sys.stderr)
    return 0


def _gnc_design(args) -> int:
    from .analysis.plots import plot_gains
    from .campaign.gains import format_schedule, schedule_summary

    plot = None if args.plot is None else _output_file("--plot", args.plot, _figure_suffixes())
    campaign = _campaign(args.campaign, aero_model=args.aero_model)
    if campaign.gnc_schedule is None:
        raise RocketmcError(f"{args.campaign}: no [gnc] section, so no gains to design")
    summary = schedule_summary(campaign.config, campaign.gnc_schedule, campaign.gnc_inputs)
    print(json.dumps(summary, indent=2) if args.json else format_schedule(summary, campaign.gnc_inputs.reference))
    if plot:
        plot_gains(summary, plot)
        print(f"wrote {plot}", file=sys.stderr)
    return 0


def _airbrakes_design(args) -> int:
    from .campaign.airbrakes import format_design

    campaign = _campaign(args.campaign)
    if campaign.airbrake_design is None:
        raise RocketmcError(f"{args.campaign}: no [airbrakes] section, so no air brakes to design")
    design = campaign.airbrake_design
    numbers = {name: None if isinstance(value, float) and math.isnan(value) else value for name, value in design._asdict().items()}
    print(json.dumps(numbers, indent=2, allow_nan=False) if args.json else format_design(design))
    return 0


def _sensors_simulate(args) -> int:
    from .analysis.sensor_log import LOG_FILES, write_sensor_log
    from .campaign.sensor_record import sensor_record

    for file, _ in LOG_FILES.values():
        _refuse_existing("--out-dir", Path(args.out_dir) / file, args.force)
    campaign = _campaign(args.campaign)
    logs = sensor_record(campaign, args.realization, args.static,
                         log=lambda line: None if args.quiet else print(line, file=sys.stderr))  # fmt: skip
    write_sensor_log(args.out_dir, logs)
    for name, frame in logs.items() if not args.quiet else ():
        print(f"wrote {Path(args.out_dir) / LOG_FILES[name][0]}: {len(frame)} samples", file=sys.stderr)
    return 0


def _site_campaign(name: str):
    """The campaign of ``navigate --site``: a campaign file, or the name of one shipped in data/campaigns."""
    from importlib import resources

    if name.endswith(".toml") or os.sep in name:
        return _campaign(name)
    shipped = resources.files("rocketmc") / "data" / "campaigns"
    if not (shipped / f"{name}.toml").is_file():
        known = sorted(p.name.removesuffix(".toml") for p in shipped.iterdir() if p.name.endswith(".toml"))
        raise RocketmcError(f"--site {name}: neither a campaign file nor a shipped campaign ({', '.join(known)})")
    return _campaign(Path(str(shipped / f"{name}.toml")))


def _navigate(args) -> int:
    from .analysis import replay as nav_replay
    from .analysis.flight_log import read_pitot_static
    from .analysis.sensor_log import read_sensor_log
    from .campaign.schema import FiltersConfig
    from .campaign.model import filter_params
    from .files import replacing

    out = None if args.out is None else _refuse_existing("--out", _output_file("--out", args.out, (".csv",)), args.force)
    campaign = _site_campaign(args.site)
    config = campaign.config
    if (FiltersConfig() if config.gnc is None else config.gnc.filters).initialisation == "pad":
        raise RocketmcError(f'{args.site}: gnc.filters.initialisation = "pad" initialises on pad samples, and a log '
                            'starts at liftoff (use "rail")')  # fmt: skip
    if not Path(args.log_dir).is_dir():
        raise RocketmcError(f"{args.log_dir}: no such folder (a sensor log: imu, baro and gnss CSV files)")
    try:
        log = read_sensor_log(args.log_dir)
    except ValueError as e:
        raise RocketmcError(str(e)) from None
    if args.static_source == "pitot":
        try:
            log["baro"] = read_pitot_static(args.log_dir)
        except (FileNotFoundError, ValueError) as e:
            raise RocketmcError(f"--static-source pitot: {e}") from None
    if args.plot_dir:  # before the replay: a folder that cannot be made is said at once
        Path(args.plot_dir).mkdir(parents=True, exist_ok=True)
    params = nav_replay.retuned(filter_params(campaign), None if args.barometer is None else args.barometer == "on",
                                args.gnss, args.gnss_after, args.gnss_std, args.field_direction_std,
                                None if args.gates is None else args.gates == "on", args.barometer_std)  # fmt: skip
    launch, site = config.launch, config.site
    say = (lambda line: None) if args.quiet else (lambda line: print(line, file=sys.stderr, flush=True))
    say(f"{args.log_dir}: {len(log['imu'])} IMU ticks, {len(log['baro'])} barometer and {len(log['gnss'])} GNSS "
        f"samples; {config.name}'s site and rail ({launch.elevation_deg:g}° toward {launch.azimuth_deg:g}°) "
        "(compiling, then replaying)")  # fmt: skip
    q_nb0 = (nav_replay.accelerometer_attitude(log, launch.azimuth_deg) if args.initial_attitude == "accelerometer"
             else nav_replay.rail_attitude(launch.elevation_deg, launch.azimuth_deg))  # fmt: skip
    nav = nav_replay.replay(log, params, q_nb0, site, barometer_max_mach=args.barometer_max_mach)
    try:
        windows = nav_replay.flight_windows(nav, log)
    except ValueError as e:
        raise RocketmcError(f"{args.log_dir}: {e}") from None
    print(nav_replay.format_navigation(nav, log, windows, params, f"{args.log_dir}: the navigation filters of "
                                       f"{config.name} replayed", args.static_source, args.barometer_max_mach))  # fmt: skip
    if out:
        with replacing(out) as partial:
            nav.to_csv(partial, index=False, lineterminator="\n")
        say(f"wrote {out}: {len(nav)} ticks")
    if args.plot_dir:
        for path in nav_replay.plot_navigation({config.name: nav}, log, windows, args.plot_dir, Path(args.log_dir).name):
            say(f"wrote {path}")
    return 0


def _fly_one(args) -> int:
    from .analysis.flight_plots import plot_flight
    from .campaign.checks import VALIDITY_OUTPUTS, outputs_validity_warnings, preflight_warnings
    from .analysis.flight_record import OUT_SUFFIXES, format_record, write_kml, write_series
    from .campaign.flights import check_realization, flight_record

    out = None if args.out is None else _refuse_existing("--out", _output_file("--out", args.out, OUT_SUFFIXES), args.force)
    kml = None if args.kml is None else _refuse_existing("--kml", _output_file("--kml", args.kml, (".kml",)), args.force)
    campaign = _campaign(args.campaign, **_switched(args))
    check_realization(campaign, args.realization)
    _warn(preflight_warnings(campaign))
    if args.plot_dir:  # before the flight: a folder that cannot be made is said at once
        Path(args.plot_dir).mkdir(parents=True, exist_ok=True)
    say = (lambda line: None) if args.quiet else (lambda line: print(line, file=sys.stderr, flush=True))
    which = "the nominal flight" if args.realization is None else f"realization {args.realization}"
    say(f"{campaign.config.name}: {which} (compiling, then flying)")
    record = flight_record(campaign, args.realization)
    print(format_record(record))
    _warn(outputs_validity_warnings(campaign, {name: [record.summary[name]] for name in VALIDITY_OUTPUTS}))
    if out:
        say(f"wrote {write_series(record, out)}: {len(record.series)} samples")
    if kml:
        say(f"wrote {write_kml(record, kml)}")
    for path in plot_flight(record, args.plot_dir) if args.plot_dir else ():
        say(f"wrote {path}")
    return 0


def _import(args) -> int:
    from .campaign.openrocket_campaign import import_openrocket
    from .files import file_stem

    out = Path(args.out) if args.out else Path(f"{file_stem(Path(args.design).stem)}.toml")
    _refuse_existing("--out", _output_file("--out", str(out), (".toml",)), args.force)
    result = import_openrocket(args.design, out, motor=args.motor, simulation=args.simulation, force=args.force)
    print("\n".join(result.lines))
    _warn(result.warnings)
    return 0


MAX_STATIC_S = 86_400.0
"""Longest static record ``sensors simulate --static`` flies [s]: a day at 50 Hz is 4.3 million periods."""
MAX_MACH = 10.0
"""Largest Mach number ``aero derivatives`` evaluates at (tables are clamped at their edge beyond theirs)."""
FLIGHTS = {"roccaraso-2021": "lynx_roccaraso_2021.toml", "euroc-2021": "lynx_euroc_2021.toml"}
"""The real flights ``validate`` knows and their built-in campaigns (data/campaigns)."""


def _validate(args) -> int:
    from importlib import resources

    from .analysis.flight_log import load_roccaraso_2021, reduce_flight
    from .analysis.validation import plot_against_log, validate_euroc, validate_roccaraso

    path = args.campaign or Path(str(resources.files("rocketmc") / "data" / "campaigns" / FLIGHTS[args.flight]))
    campaign = _campaign(path)
    if args.flight == "roccaraso-2021":
        if args.plot_dir:  # before the flight: a folder that cannot be made is said at once
            Path(args.plot_dir).mkdir(parents=True, exist_ok=True)
        reduction = reduce_flight(load_roccaraso_2021())
        checks, flight = validate_roccaraso(campaign, reduction)
        if args.plot_dir:
            plot_against_log(flight, reduction, Path(args.plot_dir) / "roccaraso_2021.png")
    else:
        checks = validate_euroc(campaign)
    if args.json:
        print(json.dumps({"flight": args.flight, "campaign": str(path), "checks": [c.to_dict() for c in checks]}, indent=2))
    else:
        print(f"{args.flight}: the nominal flight of {campaign.config.name} against the measured one")
        print(f"  {'':<40}{'simulated':>11}{'measured':>11}{'error':>10}{'bound':>9}")
        for c in checks:
            error, bound = (f"{100 * c.error:+.1f} %", f"{100 * c.tolerance:.0f} %" if c.tolerance else "") if c.relative \
                else (f"{c.error:+.2f} {c.unit}", f"{c.tolerance:g} {c.unit}" if c.tolerance else "")  # fmt: skip
            verdict = {True: "ok", False: "FAIL", None: ""}[c.passed]
            print(f"  {c.name + f' [{c.unit}]':<40}{c.simulated:>11.2f}{c.measured:>11.2f}{error:>10}{bound:>9}  {verdict}")
        if args.plot_dir and args.flight == "roccaraso-2021":
            print(f"wrote {Path(args.plot_dir) / 'roccaraso_2021.png'}")
    return 0 if all(c.passed is not False for c in checks) else 1


def _budget(args) -> int:
    from .analysis.budget import BudgetError, budget_rows, fly_rows, format_budget, plot_budget, summarize_budget

    plot = None if args.plot is None else _output_file("--plot", args.plot, _figure_suffixes())
    campaign = _campaign(args.campaign, n_realizations=args.n, seed=args.seed, aero_model=args.aero_model)
    sources = None if args.sources is None else [name for name in args.sources.split(",") if name]
    try:
        rows = budget_rows(campaign, sources)
    except BudgetError as e:
        raise RocketmcError(f"{args.campaign}: {e}") from None
    cfg = campaign.config

    def log(message):
        if not args.quiet:
            print(message, file=sys.stderr, flush=True)

    flown = sum(row.campaign is not None for row in rows)
    log(f"{cfg.name}: error budget, {flown} rows of {cfg.n_realizations} realizations, seed {cfg.seed} (one "
        "compilation per row)")  # fmt: skip
    summary = summarize_budget(campaign, fly_rows(rows, log))
    print(json.dumps(summary, indent=2, allow_nan=False) if args.json else format_budget(summary))
    if plot:
        plot_budget(summary, plot)
        print(f"wrote {plot}", file=sys.stderr)
    return 0


def _bench(args) -> int:
    from .bench import DEFAULT_CAMPAIGN, BenchError, format_report, run_benchmarks
    from .campaign import ConfigError

    campaign = args.campaign or DEFAULT_CAMPAIGN
    try:
        report = run_benchmarks(campaign, tuple(args.n), tuple(args.aero_model), tuple(args.precision),
                                args.chunk_size, log=lambda line: print(line, file=sys.stderr, flush=True))  # fmt: skip
    except ConfigError as e:
        raise RocketmcError(f"{campaign}: {e}") from None
    except BenchError as e:
        return _fail(str(e), 1)
    print(json.dumps(report, indent=2) if args.json else format_report(report))
    return 0


OLD_SPELLINGS = {"--plot": "--plot-dir", "--out": "--out-dir", "--n": "-n", "--models": "--aero-model"}
"""Spellings users relied on before an option was renamed, and the name it has now (still accepted where it was:
``navigate``/``validate --plot`` and ``sensors simulate --out`` took folders, ``bench --n`` and ``--models``).
Everywhere else an option has one spelling and one meaning: ``--out``/``--plot`` a file, ``--out-dir``/
``--plot-dir`` a folder, ``-n`` realizations, ``--aero-model`` the aerodynamic model(s) (tests/test_cli.py)."""


def _bounded(kind: type, low: float | None, high: float | None, what: str, above: bool = False):
    """An argparse type: a finite ``kind`` number from ``low`` (excluded when ``above``) to ``high`` (None: no
    bound), else the one-line error "must be <what>"."""

    def parse(text: str):
        try:
            value = kind(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
        inside = math.isfinite(value) and (low is None or (value > low if above else value >= low))
        if not (inside and (high is None or value <= high)):
            raise argparse.ArgumentTypeError(f"must be {what}, got {text}")
        return value

    return parse


def _positive(what: str):
    """An argparse type: a positive finite number, said to be a ``what``."""
    return _bounded(float, 0.0, None, f"a positive {what}", above=True)


COUNT = _bounded(int, 1, None, "at least 1")
PERCENTAGE = _bounded(float, 0.0, 100.0, "a percentage in (0, 100]", above=True)


def _flight_switches(parser: argparse.ArgumentParser) -> None:
    """The options that fly a campaign otherwise: the aerodynamic model, the controller and the sensors."""
    parser.add_argument("--aero-model", choices=("interpolated", "simplified", "linear"),
                        help="aerodynamic model (overrides rocket.aero.model)")  # fmt: skip
    parser.add_argument("--controller", choices=("on", "off"),
                        help="off: the same flights with the canards neutral (no [gnc]); on: the campaign's [gnc], "
                             "or its defaults if it has none")  # fmt: skip
    parser.add_argument("--sensors", choices=("on", "off"),
                        help="on: the controller flies on raw sensors (the campaign's [avionics], or the thesis's "
                             "parts); off: no sensors, the controller on perfect navigation")  # fmt: skip
    parser.add_argument("--airbrakes", choices=("off",), help="off: the same flights without the campaign's [airbrakes]")


def _switched(args) -> dict:
    """The campaign overrides of ``_flight_switches``' options (None: the campaign's own)."""
    on = lambda switch: None if switch is None else switch == "on"  # noqa: E731
    return {"aero_model": args.aero_model, "controller": on(args.controller), "sensors": on(args.sensors),
            "airbrakes": on(args.airbrakes)}  # fmt: skip


def build_parser() -> argparse.ArgumentParser:
    """The ``rocketmc`` argument parser with every subcommand."""
    from .campaign.run import MAX_TRAJECTORIES, TRAJECTORY_INTERVAL_S

    parser = _Parser(prog="rocketmc", description="Monte Carlo dispersion of sounding-rocket flights.")
    parser.add_argument("--version", action="version", version=f"rocketmc {__version__}")
    commands = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    run = commands.add_parser("run", help="fly a campaign and write its HDF5 result file")
    run.add_argument("campaign", help="campaign file (TOML)")
    run.add_argument("-n", type=COUNT, help="number of realizations (overrides the campaign)")
    run.add_argument("--seed", type=int, help="master seed (overrides the campaign)")
    run.add_argument("--out", help="result file (default: <campaign name>.h5)")
    run.add_argument("--chunk-size", type=COUNT, help="realizations per compiled batch")
    run.add_argument("--quiet", action="store_true", help="no progress messages (errors and warnings only)")
    run.add_argument("--until-converged", type=PERCENTAGE, metavar="PCT",
                     help="add chunks (up to N) until the 95 %% ellipse area's 95 %% bootstrap interval is "
                          "narrower than PCT %% of the area; the file keeps the N reached")  # fmt: skip
    replace = run.add_mutually_exclusive_group()
    replace.add_argument("--force", action="store_true", help="replace an existing result file")
    replace.add_argument("--resume", action="store_true",
                     help="complete the partial run left in OUT.partial/ by a killed run (same campaign and options)")  # fmt: skip
    _flight_switches(run)
    run.add_argument("--trajectories", metavar="I,J,...",
                     help=f"keep the time series of these realizations (at most {MAX_TRAJECTORIES}), decimated, in the "
                          "file's /trajectories: each flown after the chunks as fly flies it")  # fmt: skip
    run.add_argument("--trajectory-interval", type=_positive("time in seconds"), default=TRAJECTORY_INTERVAL_S, metavar="S",
                     help="with --trajectories, keep the first sample of each S seconds and the last (default "
                          "%(default)g)")  # fmt: skip
    cluster = run.add_mutually_exclusive_group()
    cluster.add_argument("--scheduler", metavar="ADDRESS",
                         help="fly the chunks on the Dask cluster of this scheduler (tcp://host:8786; needs "
                              "the 'dask' extra)")  # fmt: skip
    cluster.add_argument("--workers", type=_bounded(int, 1, CORES, f"from 1 to the {CORES} core(s) of this machine (one process per core)"), metavar="N",
                         help="fly the chunks on a local Dask cluster of N worker processes sharing the cores "
                              "(needs the 'dask' extra)")  # fmt: skip
    report = commands.add_parser("report", help="summarize a result file: ellipses and statistics")
    report.add_argument("file", help="HDF5 result file")
    report.add_argument("--plot", help="write the impact plot with 50/95/99 %% ellipses to this PNG")
    report.add_argument("--json", action="store_true", help="print the summary as JSON")
    report.add_argument("--force", action="store_true", help="replace existing --map and --csv files")
    report.add_argument("--map", action="append", metavar="FILE",
                        help="write the impact points and ellipses around the launch site as KML (.kml) or "
                             "GeoJSON (.geojson); repeatable")  # fmt: skip
    report.add_argument("--csv", metavar="FILE",
                        help="write one row per realization (status, outputs, inputs; columns with units) to this CSV")
    report.add_argument("--plot-dir", metavar="DIR",
                        help="write histograms of apogee, impact distance from the pad and landing speed (PNG) "
                             "to this folder")  # fmt: skip
    report.add_argument("--outside-radius", type=_positive("distance in metres"), metavar="M",
                        help="the probability of landing more than M metres from the pad, with its exact 95 %% "
                             "interval (flights without an impact point counted as outside)")  # fmt: skip
    report.add_argument("--outside-polygon", metavar="FILE",
                        help="the probability of landing outside the range's allowed area, a GeoJSON Polygon or a "
                             "CSV of lat_deg,lon_deg vertices; counted as --outside-radius")  # fmt: skip
    compare = commands.add_parser("compare", help="compare the landing dispersion of result files with the first's")
    compare.add_argument("files", nargs="+", metavar="FILE",
                         help="HDF5 result files, at least two; the first is the baseline")  # fmt: skip
    compare.add_argument("--json", action="store_true", help="print the comparison as JSON")
    compare.add_argument("--plot", help="write the impact points and 95 %% ellipses of all files to this PNG")
    sensitivity = commands.add_parser(
        "sensitivities", help="each flight's derivatives of its landing point, apogee and landing speed with respect "
                              "to its inputs, and each dispersed input's share of their spread")  # fmt: skip
    sensitivity.add_argument("campaign", help="campaign file (TOML)")
    sensitivity.add_argument("-n", type=COUNT, help="number of realizations (overrides the campaign)")
    sensitivity.add_argument("--seed", type=int, help="master seed (overrides the campaign)")
    sensitivity.add_argument("--wrt", metavar="PATH,...",
                             help="design numbers (dotted paths, e.g. rocket.dry_mass_kg) to differentiate with "
                                  "respect to, besides every continuously dispersed input")  # fmt: skip
    sensitivity.add_argument("--out", help="result file with /derivatives (default: <campaign name>_sensitivities.h5)")
    sensitivity.add_argument("--chunk-size", type=COUNT,
                             help=f"realizations per compiled batch (default {SENSITIVITY_CHUNK}: derivatives hold more "
                                  "memory per flight than a run)")  # fmt: skip
    sensitivity.add_argument("--json", action="store_true", help="print the shares as JSON")
    sensitivity.add_argument("--plot", help="write the tornado plot of the shares to this PNG")
    sensitivity.add_argument("--quiet", action="store_true", help="no progress messages (errors and warnings only)")
    replace = sensitivity.add_mutually_exclusive_group()
    replace.add_argument("--force", action="store_true", help="replace an existing result file")
    replace.add_argument("--resume", action="store_true", help="complete the partial run left in OUT.partial/")
    _flight_switches(sensitivity)
    tuner = commands.add_parser("tune", help="tune the controller's guidance numbers or the air brakes' gains by "
                                             "gradient descent through a batch of training flights, and write the "
                                             "tuned campaign")  # fmt: skip
    tuner.add_argument("campaign", help="campaign file (TOML) with a [gnc] or an [airbrakes] section")
    tuner.add_argument("--params", required=True, metavar="PATH[=START],...",
                       help="numbers to tune, each from the campaign's value or from START, e.g. "
                            "gnc.guidance.gain,gnc.guidance.wind_gain=4 (the upwind aim, off unless set, from 1 "
                            "without START) or airbrakes.reference.kp_n_s_per_m,airbrakes.reference.ki_n_per_m; a "
                            "gradient finds the nearest minimum: start where a coarse scan is lowest")  # fmt: skip
    tuner.add_argument("--objective", choices=("ellipse_area", "apogee_error"), default="ellipse_area",
                       help="the 95 %% landing ellipse's area, or the apogee's RMS error to --apogee-target-m")
    tuner.add_argument("--apogee-target-m", type=_bounded(float, 0.0, MAX_ALTITUDE_M, "a height above the pad", above=True),
                       help="the target of --objective apogee_error [m above the pad] (default: [airbrakes]' "
                            "target_apogee_m)")  # fmt: skip
    tuner.add_argument("--train", type=COUNT, default=256, help="training flights (default 256; the campaign's seed + 1)")
    tuner.add_argument("--test", type=_bounded(int, 0, None, "0 or more"), default=1000,
                       help="held-out flights (the campaign's own seed) flown before and after, and with the "
                            "controller off (default 1000; 0: none)")  # fmt: skip
    tuner.add_argument("--train-turbulence", action="store_true",
                       help="train on flights with the campaign's turbulence (by default without: its gusts make the "
                            "objective jump where a derivative sees none)")  # fmt: skip
    tuner.add_argument("--steps", type=COUNT, default=30, help="Adam steps (default 30)")
    tuner.add_argument("--learning-rate", type=_bounded(float, 0.0, 1.0, "in (0, 1]", above=True), default=0.05,
                       help="Adam's step, in units of each number's starting value (default 0.05)")
    tuner.add_argument("--out", required=True, help="the tuned campaign file to write (.toml; extends CAMPAIGN)")
    tuner.add_argument("--force", action="store_true", help="replace an existing --out")
    tuner.add_argument("--plot", help="write the objective's history and the tuned numbers to this PNG")
    tuner.add_argument("--json", action="store_true", help="print the result as JSON")
    tuner.add_argument("--quiet", action="store_true", help="no progress messages (errors and warnings only)")
    _flight_switches(tuner)
    aero = commands.add_parser("aero", help="aerodynamic coefficients of a rocket")
    aero_commands = aero.add_subparsers(dest="aero_command", required=True, parser_class=_Parser)
    derivatives = aero_commands.add_parser("derivatives", help="linear coefficients at a Mach number")
    derivatives.add_argument("rocket", help="a preset name (lynx) or a campaign file (its rocket)")
    derivatives.add_argument("--mach", type=_bounded(float, 0.0, MAX_MACH, f"a Mach number in [0, {MAX_MACH:g}]"), default=0.3, help="Mach number (default 0.3)")
    derivatives.add_argument("--altitude", type=_bounded(float, -2000.0, MAX_ALTITUDE_M, f"in the standard atmosphere's [-2000, {MAX_ALTITUDE_M:.0f}] m"), default=0.0, help="altitude above sea level [m] (default 0)")
    derivatives.add_argument("--json", action="store_true", help="print as JSON")
    derivatives.add_argument("--plot", metavar="FILE", help="also draw CA0 (the drag at α = 0), CNα and the centre of "
                             "pressure against Mach, with the CG at liftoff and burnout, into this figure (.png, .svg, .pdf)")  # fmt: skip
    gnc = commands.add_parser("gnc", help="the closed loop of a campaign")
    gnc_commands = gnc.add_subparsers(dest="gnc_command", required=True, parser_class=_Parser)
    design = gnc_commands.add_parser("design", help="the LQI gain schedule designed at set-up, per grid point")
    design.add_argument("campaign", help="campaign file (TOML) with a [gnc] section")
    design.add_argument("--json", action="store_true", help="print everything as JSON, with the full gain matrices")
    design.add_argument("--plot", help="write the main gains and spectral radius against speed to this PNG")
    design.add_argument("--aero-model", choices=("interpolated", "simplified", "linear"),
                        help="aerodynamic model (overrides rocket.aero.model)")  # fmt: skip
    airbrakes = commands.add_parser("airbrakes", help="the air brakes of a campaign")
    airbrakes_commands = airbrakes.add_subparsers(dest="airbrakes_command", required=True, parser_class=_Parser)
    brake_design = airbrakes_commands.add_parser(
        "design", help="the air brakes' gain designed at set-up: the nominal flight where they may open, their authority")
    brake_design.add_argument("campaign", help="campaign file (TOML) with an [airbrakes] section")
    brake_design.add_argument("--json", action="store_true", help="print as JSON")
    sensors = commands.add_parser("sensors", help="the simulated sensors of a campaign")
    sensors_commands = sensors.add_subparsers(dest="sensors_command", required=True, parser_class=_Parser)
    simulate = sensors_commands.add_parser(
        "simulate", help="one realization's sensor outputs, as CSV files like the real Lynx log's")
    simulate.add_argument("campaign", help="campaign file (TOML) with an [avionics] section")
    simulate.add_argument("--realization", type=_bounded(int, 0, None, "at least 0"), default=0, metavar="I",
                          help="the realization whose drawn errors and gusts are flown (default 0)")  # fmt: skip
    simulate.add_argument("--static", type=_bounded(float, 0.0, MAX_STATIC_S, f"a time in (0, {MAX_STATIC_S:g}] s", above=True), metavar="SECONDS",
                          help="instead, the rocket at rest on the pad for this long (noise analysis)")  # fmt: skip
    simulate.add_argument("--out-dir", "--out", dest="out_dir", required=True, metavar="DIR",
                          help="folder for the CSV files (--out: its old spelling)")  # fmt: skip
    simulate.add_argument("--force", action="store_true", help="replace the CSV files of a log already in --out")
    simulate.add_argument("--quiet", action="store_true", help="no progress messages (errors only)")
    navigate = commands.add_parser(
        "navigate", help="the navigation filters replayed on a sensor log (the real Roccaraso one or a simulated one)")
    navigate.add_argument("log_dir", metavar="LOG_DIR", help="folder of the log's CSV files (imu, baro, gnss)")
    navigate.add_argument("--site", default="lynx_roccaraso_2021", metavar="NAME|CAMPAIGN.toml",
                          help="the campaign whose site, rail (the attitude at liftoff) and [gnc.filters] tuning are "
                               "used: a shipped campaign's name or a campaign file (default: lynx_roccaraso_2021)")  # fmt: skip
    navigate.add_argument("--out", metavar="NAV.csv", help="write the estimates at every tick to this CSV file")
    navigate.add_argument("--plot-dir", "--plot", dest="plot_dir", metavar="DIR",
                          help="folder for the figures (height, velocity, its direction, attitude; --plot: its old spelling)")  # fmt: skip
    navigate.add_argument("--barometer", choices=("on", "off"), help="the barometric height update (default: the campaign's)")
    navigate.add_argument("--static-source", choices=("baro", "pitot"), default="baro",
                          help="the static pressure of the barometer's samples (the update and the barometric height "
                               "compared with): the log's barometer, or the static port of its pitot_42hz.csv (the "
                               "real log's) (default: baro)")  # fmt: skip
    navigate.add_argument("--barometer-std", type=_positive("height in metres"), metavar="M",
                          help="the barometric height's standard deviation [m] (default: the campaign's)")
    navigate.add_argument("--barometer-max-mach", type=_positive("Mach number"), metavar="M",
                          help="lock the barometer out while the filters' estimated speed exceeds Mach M "
                               "(default: never)")  # fmt: skip
    navigate.add_argument("--gnss", choices=("all", "horizontal"),
                          help="GNSS updates of every axis or of north and east only (default: the campaign's)")  # fmt: skip
    navigate.add_argument("--gnss-after", type=_bounded(float, 0.0, None, "a time of at least 0 s"), metavar="S",
                          help="use GNSS fixes from S seconds after liftoff (default: the campaign's)")  # fmt: skip
    navigate.add_argument("--gnss-std", type=_positive("standard deviation"), nargs=2, metavar=("M", "MPS"),
                          help="the GNSS's position [m] and velocity [m/s] standard deviations, every axis "
                               "(default: the campaign's)")  # fmt: skip
    navigate.add_argument("--field-direction-std", type=_positive("standard deviation"), metavar="S",
                          help="the magnetometer's field direction standard deviation (default: the campaign's)")  # fmt: skip
    navigate.add_argument("--initial-attitude", choices=("rail", "accelerometer"), default="rail",
                          help="the attitude at liftoff: the campaign's rail elevation and azimuth, or the pitch and "
                               "roll of the log's first accelerometer sample with the rail's azimuth (default: rail)")  # fmt: skip
    navigate.add_argument("--gates", choices=("on", "off"),
                          help="off: no innovation gate on any update (default: the campaign's gates)")  # fmt: skip
    navigate.add_argument("--force", action="store_true", help="replace an existing --out file")
    navigate.add_argument("--quiet", action="store_true", help="no progress messages (errors only)")
    fly = commands.add_parser("fly", help="one flight's full time series, summary, figures and KML path")
    fly.add_argument("campaign", help="campaign file (TOML)")
    fly.add_argument("--realization", type=int, metavar="I",
                     help="fly realization I as a campaign run flies it: bit for bit, within rounding (~1e-11) with "
                          "navigation filters (default: the nominal flight)")  # fmt: skip
    fly.add_argument("--out", metavar="FLIGHT.csv|.h5", help="write the time series (CSV or HDF5, with units)")
    fly.add_argument("--plot-dir", metavar="DIR", help="folder for the figures (path, altitude and speed, angles, margin)")
    fly.add_argument("--kml", metavar="PATH", help="write the flight path as KML (Google Earth)")
    _flight_switches(fly)
    fly.add_argument("--force", action="store_true", help="replace existing --out and --kml files")
    fly.add_argument("--quiet", action="store_true", help="no progress messages (errors only)")
    validate = commands.add_parser("validate", help="fly a real flight's campaign and compare with what was measured")
    validate.add_argument("flight", choices=sorted(FLIGHTS), help="the flight")
    validate.add_argument("--campaign", help="another campaign file to fly instead of the built-in one")
    validate.add_argument("--plot-dir", "--plot", dest="plot_dir", metavar="DIR",
                          help="folder for the overlay plots (roccaraso-2021; --plot: its old spelling)")  # fmt: skip
    validate.add_argument("--json", action="store_true", help="print the comparison as JSON")
    budget = commands.add_parser(
        "budget", help="the GNC error budget: a closed-loop campaign flown with each navigation error source alone",
        description="Fly a closed-loop campaign (navigation 'filters' or 'sensors') with each navigation error source "
        "alone, with all (the campaign), with none (the navigation on perfect sensors and the truth's field), on perfect navigation and "
        "with the controller off, every row with the same seed and N (the same winds and draws): the 95 % landing "
        "ellipse of each row, its paired ratios to the others, the navigation and control errors and the failed "
        "flights. One compilation per row flown; no result file.",
    )  # fmt: skip
    budget.add_argument("campaign", help="campaign file (TOML) with [gnc] navigation 'filters' or 'sensors'")
    budget.add_argument("-n", type=COUNT, help="number of realizations (overrides the campaign)")
    budget.add_argument("--seed", type=int, help="master seed (overrides the campaign)")
    budget.add_argument("--aero-model", choices=("interpolated", "simplified", "linear"),
                        help="aerodynamic model (overrides rocket.aero.model)")  # fmt: skip
    budget.add_argument("--sources", metavar="NAME,...",
                        help="the error sources flown alone, separated by commas (default: all of them: "
                             "accelerometer, gyroscope, magnetometer, barometer, gnss, canard_feedback, field_model)")  # fmt: skip
    budget.add_argument("--json", action="store_true", help="print the budget as JSON")
    budget.add_argument("--plot", help="write a bar chart of each row's ellipse area to this PNG")
    budget.add_argument("--quiet", action="store_true", help="no progress messages (errors only)")
    ork = commands.add_parser(
        "import", help="write a campaign from an OpenRocket design (.ork): geometry, masses, recovery, site, wind, motor",
        description="Read an OpenRocket design and write a commented campaign file (each value with where it came "
        "from) flying the design's motor: from the library when it is there, else the Thrust column of the chosen "
        "simulation's stored flight, written beside the campaign. "
        "What rocketmc cannot fly (pods, clusters, a second stage, tube fins, a body whose diameter changes other than "
        "by an aft boat-tail) is refused in one line naming the component; nothing is written then.",
    )  # fmt: skip
    ork.add_argument("design", metavar="ROCKET.ork", help="OpenRocket design (.ork, or its bare rocket.ork XML)")
    ork.add_argument("--motor", metavar="NAME|FILE",
                     help="a motor of the library by designation (rocketmc motors), or a thrust curve file (RASP .eng, "
                          "RockSim .rse or CSV); default: the design's motor if the library has it, else the curve "
                          "the simulation stored")  # fmt: skip
    ork.add_argument("--simulation", type=COUNT, metavar="K",
                     help="the design's simulation giving the motor, site, rail and wind, 1-based (default: 1)")  # fmt: skip
    ork.add_argument("--out", metavar="CAMPAIGN.toml",
                     help="the campaign file (default: the design's name, .toml, in this folder); the thrust curve is "
                          "written beside it as <name>_thrust.csv")  # fmt: skip
    ork.add_argument("--force", action="store_true", help="replace existing campaign and thrust files")
    bench = commands.add_parser(
        "bench", help="measure this machine: flights/s, compile time, peak memory, float32 against float64",
        description="Fly a campaign for each N, aerodynamic model and precision, each in a fresh process: "
        "flights/s after compilation, compile time, peak resident memory and failed flights; with both precisions, "
        "the distances between the impact points of the same realizations in float32 and float64; then the vmapped "
        "batch against single flights in a loop and the interpolated aerodynamics against the simplified, timed "
        "together. A few minutes with the defaults.",
    )  # fmt: skip
    bench.add_argument("--campaign", metavar="FILE", help="campaign file (default: the built-in lynx_nominal)")
    bench.add_argument("-n", "--n", dest="n", type=COUNT, nargs="+", default=[1000], metavar="N",
                       help="numbers of realizations, one measurement each (default: 1000)")  # fmt: skip
    bench.add_argument("--aero-model", "--models", dest="aero_model", nargs="+", metavar="MODEL",
                       choices=("simplified", "interpolated", "linear"),
                       default=["simplified", "interpolated"],
                       help="aerodynamic models among simplified, interpolated, linear "
                            "(default: simplified interpolated)")  # fmt: skip
    bench.add_argument("--precision", nargs="+", choices=("float64", "float32"), metavar="PRECISION",
                       default=["float64", "float32"], help="float64 and/or float32 (default: both)")  # fmt: skip
    bench.add_argument("--chunk-size", type=COUNT, metavar="C",
                       help="realizations per compiled chunk (default: the campaign's)")  # fmt: skip
    bench.add_argument("--json", action="store_true", help="print the results as JSON instead of a table")
    motors = commands.add_parser(
        "motors", help="list the built-in motor library (what rocket.motor.designation names)",
        description="The built-in library of commercial motors (RASP .eng certification curves): per motor its "
        "file's name, designation, manufacturer, diameter and length, the curve's total impulse, NAR class, average "
        "thrust over its burn time (thrust at or above 5 % of its maximum), and the propellant and total masses.",
    )  # fmt: skip
    motors.add_argument("search", nargs="?", help="only the motors whose name, designation or manufacturer contains "
                        "this (case and punctuation ignored: l1350, cesaroni, K-400)")  # fmt: skip
    return parser


def _motors(args) -> int:
    from .analysis.motors import motor_table
    from .dynamics.motor_library import matching_motors

    entries = matching_motors(args.search)
    if not entries:
        raise RocketmcError(f"no motor of the library matches {args.search!r} (`rocketmc motors` lists them all)")
    print(motor_table(entries))
    return 0


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if len(getattr(args, "files", [])) == 1:
        parser.error("compare needs at least two result files")
    command = {"run": _run, "report": _report, "compare": _compare, "aero": _aero_derivatives, "gnc": _gnc_design,
               "airbrakes": _airbrakes_design,
               "sensors": _sensors_simulate, "navigate": _navigate, "fly": _fly_one, "validate": _validate, "bench": _bench, "budget": _budget,
               "motors": _motors, "import": _import,
               "sensitivities": _sensitivities, "tune": _tune}  # fmt: skip
    try:
        return command[args.command](args)
    except RocketmcError as e:  # bad input, a partial run or cluster that cannot be used, a full disk
        return _fail(str(e))
    except BrokenPipeError:  # `rocketmc report FILE | head`: the reader has gone, nothing more to say
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())  # no second error at exit's flush
        return 128 + signal.SIGPIPE
    except OSError as e:  # a file that cannot be read or written
        return _fail(f"{e.filename}: {e.strerror}" if e.filename else str(e))
    except KeyboardInterrupt:
        return _fail("interrupted", 128 + signal.SIGINT)


def _fail(message: str, code: int = 2) -> int:
    """Say ``message`` in one line on stderr; return the exit code."""
    print(f"rocketmc: error: {' '.join(message.split())}", file=sys.stderr)
    return code


if __name__ == "__main__":
    sys.exit(main())

"""The ``rocketmc`` command line: ``run`` a campaign, ``report`` on its result file."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # one line, exit code 2
        self.exit(2, f"rocketmc: error: {message}\n")


def _run(args) -> int:
    from .campaign import ConfigError, ResultWriter, load_campaign, run_chunks

    try:
        campaign = load_campaign(args.campaign).with_overrides(n_realizations=args.n, seed=args.seed)
    except ConfigError as e:
        print(f"rocketmc: error: {args.campaign}: {e}", file=sys.stderr)
        return 2
    cfg = campaign.config
    out = Path(args.out or f"{cfg.name}.h5")
    chunk_size = min(args.chunk_size or cfg.simulation.chunk_size, cfg.n_realizations)
    n_chunks = -(-cfg.n_realizations // chunk_size)
    log = lambda msg: print(msg, file=sys.stderr, flush=True)  # noqa: E731
    log(f"{cfg.name}: {cfg.n_realizations} realizations, seed {cfg.seed}, {n_chunks} chunk(s) of {chunk_size}")
    runs = run_chunks(campaign, chunk_size)
    log(f"compiled in {next(runs):.1f} s")
    flown, seconds = 0, 0.0
    with ResultWriter(out, campaign, chunk_size) as writer:
        for i, chunk in enumerate(runs):
            writer.write(chunk, i)
            n = len(chunk.outputs["status"])
            flown, seconds = flown + n, seconds + chunk.seconds
            failed = int((chunk.outputs["status"] != 0).sum())
            log(f"chunk {i + 1}/{n_chunks}: {n} flights in {chunk.seconds:.1f} s "
                f"({n / chunk.seconds:.0f} flights/s){f', {failed} not ok' if failed else ''}")  # fmt: skip
        writer.finish()
    log(f"wrote {out} ({flown} flights, {flown / seconds:.0f} flights/s after compilation)")
    return 0


def _report(args) -> int:
    from .analysis import format_summary, load_run, plot_impacts, summarize

    if not Path(args.file).is_file():
        print(f"rocketmc: error: {args.file}: file not found", file=sys.stderr)
        return 2
    try:
        run = load_run(args.file)
    except (OSError, ValueError) as e:
        print(f"rocketmc: error: {args.file}: {e}", file=sys.stderr)
        return 2
    summary = summarize(run)
    print(json.dumps(summary, indent=2, allow_nan=False) if args.json else format_summary(summary))
    if args.plot:
        plot_impacts(run, path=args.plot)
        print(f"wrote {args.plot}", file=sys.stderr)
    return 0


def main(argv: list[str] | None = None) -> int:
    parser = _Parser(prog="rocketmc", description="Monte Carlo dispersion of sounding-rocket flights.")
    from . import __version__

    parser.add_argument("--version", action="version", version=f"rocketmc {__version__}")
    commands = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    run = commands.add_parser("run", help="fly a campaign and write its HDF5 result file")
    run.add_argument("campaign", help="campaign file (TOML)")
    run.add_argument("-n", type=int, help="number of realizations (overrides the campaign)")
    run.add_argument("--seed", type=int, help="master seed (overrides the campaign)")
    run.add_argument("--out", help="result file (default: <campaign name>.h5)")
    run.add_argument("--chunk-size", type=int, help="realizations per compiled batch")
    report = commands.add_parser("report", help="summarize a result file: ellipses and statistics")
    report.add_argument("file", help="HDF5 result file")
    report.add_argument("--plot", help="write the impact plot with 50/95/99 %% ellipses to this PNG")
    report.add_argument("--json", action="store_true", help="print the summary as JSON")
    args = parser.parse_args(argv)
    for name in ("n", "chunk_size"):
        if getattr(args, name, None) is not None and getattr(args, name) < 1:
            parser.error(f"--{name.replace('_', '-')} must be at least 1")
    return {"run": _run, "report": _report}[args.command](args)


if __name__ == "__main__":
    sys.exit(main())

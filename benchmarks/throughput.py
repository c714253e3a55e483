"""The full benchmark set (``rocketmc bench`` with every size): both aerodynamic models and both
precisions at N = 1 000, 10 000 and 100 000, float32 against float64 on the same realizations and
the ratios timed together (the batch against a loop on every core, the model costs on one); the readable table on stdout, the JSON in OUT.

    python benchmarks/throughput.py OUT.json [--campaign FILE] [--n 1000 10000 100000] [--chunk-size C]

Each measurement runs in its own process, so the peak RSS per N shows whether memory stays flat in N
(it should: the chunks have a fixed size). Roughly half an hour on the 2-core development machine
(an estimate: four runs of 100 000 flights at a few hundred flights/s dominate).
"""

from __future__ import annotations

import argparse
import json
import sys

from rocketmc.bench import DEFAULT_CAMPAIGN, MODELS, PRECISIONS, format_report, run_benchmarks


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", help="JSON file to write")
    parser.add_argument("--campaign", default=DEFAULT_CAMPAIGN)
    parser.add_argument("--n", type=int, nargs="+", default=[1_000, 10_000, 100_000])
    parser.add_argument("--chunk-size", type=int)
    args = parser.parse_args()
    report = run_benchmarks(args.campaign, tuple(args.n), MODELS, PRECISIONS, args.chunk_size,
                            log=lambda line: print(line, file=sys.stderr, flush=True))  # fmt: skip
    with open(args.out, "w") as f:
        json.dump(report, f, indent=2)
    print(format_report(report))


if __name__ == "__main__":
    main()

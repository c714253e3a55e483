"""OpenRocket's designs imported and flown by rocketmc, against OpenRocket's own stored simulations.

    python benchmarks/openrocket_examples.py FOLDER [--all-simulations] [--json FILE]

Imports every .ork in FOLDER (``rocketmc import``: the first simulation's motor, site, rail and wind, or each
simulation with stored flight data with ``--all-simulations``), loads the campaign, flies its nominal flight (as
``rocketmc fly`` does) and prints, per design and simulation, OpenRocket's stored apogee, maximum speed, time to
apogee, launch-rod speed and maximum Mach number beside rocketmc's, and the mass and CG at t = 0 (motor included) beside the stored ones.
Designs rocketmc refuses are listed with the refusal. The campaigns are written to a temporary folder.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
from pathlib import Path

import numpy as np

from rocketmc.campaign import load_campaign
from rocketmc.campaign.flights import flight_record
from rocketmc.campaign.openrocket import OpenRocketError, read_design, read_simulation
from rocketmc.campaign.openrocket_campaign import import_openrocket

COMPARED = (("apogee [m]", "maxaltitude", "apogee"), ("max speed [m/s]", "maxvelocity", "max_speed"),
            ("time to apogee [s]", "timetoapogee", "apogee_time"), ("rod speed [m/s]", "launchrodvelocity", "rod_speed"),
            ("max Mach", "maxmach", "max_mach"),
            ("mass t=0 [kg]", "Mass", "mass"), ("CG t=0 [m]", "CG location", "cg"))  # fmt: skip
"""(label, OpenRocket's flightdata attribute or t = 0 column, rocketmc's key)."""


def fly(design_path: Path, simulation: int, folder: Path) -> dict:
    """Import simulation ``simulation`` of the design, fly the nominal flight; OpenRocket's and rocketmc's figures."""
    out = folder / f"{design_path.stem.replace(' ', '_')}_{simulation}.toml"
    result = import_openrocket(design_path, out, simulation=simulation, force=True)
    sim = read_simulation(read_design(design_path), simulation)
    record = flight_record(load_campaign(out))
    series, summary = record.series, record.summary
    ours = {"apogee": summary["apogee_agl_m"], "max_speed": float(np.max(series["speed"])),
            "apogee_time": summary["apogee_time_s"], "rod_speed": summary["rail_exit_speed_mps"],
            "max_mach": float(np.max(series["mach"])),
            "mass": float(series["mass"].iloc[0]), "cg": float(series["cg"].iloc[0])}  # fmt: skip
    theirs = {key: sim.summary.get(attribute, sim.at_liftoff(attribute)) for _, attribute, key in COMPARED}
    return {"design": design_path.stem, "simulation": f"{simulation} {sim.name} ({result.lines[0].split('motor ')[-1]})",
            "openrocket": theirs, "rocketmc": ours, "status": record.status,
            "dry": {"computed": [float(v) for v in result.computed],
                    "stored": None if result.stored is None else [float(v) for v in result.stored]},
            "warnings": result.warnings}  # fmt: skip


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folder", help="a folder of OpenRocket designs (.ork)")
    parser.add_argument("--all-simulations", action="store_true", help="every simulation with stored flight data")
    parser.add_argument("--json", help="also write the rows to this file")
    args = parser.parse_args()
    rows, refused = [], []
    with tempfile.TemporaryDirectory() as folder:
        for path in sorted(Path(args.folder).glob("*.ork")):
            try:
                design = read_design(path)
            except OpenRocketError as e:
                refused.append(str(e))
                continue
            flown = [k for k in range(1, len(design.simulations) + 1) if read_simulation(design, k).columns]
            for k in flown if args.all_simulations else flown[:1]:
                rows.append(fly(path, k, Path(folder)))
                print(f"flew {path.name}, simulation {k}", file=sys.stderr, flush=True)
    head = "| design | simulation (motor) | " + " | ".join(label for label, _, _ in COMPARED) + " |"
    print(head + "\n|" + "---|" * (2 + len(COMPARED)))
    for row in rows:
        cells = [f"{row['openrocket'][key]:.4g} / {row['rocketmc'][key]:.4g} ({_percent(row, key)})"
                 for _, _, key in COMPARED]  # fmt: skip
        print(f"| {row['design']} | {row['simulation']} | " + " | ".join(cells) + " |")
    print("\nEach cell: OpenRocket's stored value / rocketmc's (difference).")
    print("\nDry rocket (motor out), computed by the import against the stored t = 0 less the motor "
          "(mass [kg], CG [m], Ixx, Iyy [kg·m²]):")  # fmt: skip
    for row in rows:
        computed, stored = row["dry"]["computed"], row["dry"]["stored"]
        print(f"  {row['design']}, {row['simulation']}: " + ", ".join(
            f"{c:.4g} / {s:.4g}" for c, s in zip(computed, stored or [float('nan')] * 4)))
    for line in refused:
        print(f"refused: {line}")
    if args.json:
        Path(args.json).write_text(json.dumps({"rows": rows, "refused": refused}, indent=2))
    return 0


def _percent(row: dict, key: str) -> str:
    theirs, ours = row["openrocket"][key], row["rocketmc"][key]
    return f"{100 * (ours - theirs) / theirs:+.1f} %" if theirs else "n/a"


if __name__ == "__main__":
    sys.exit(main())

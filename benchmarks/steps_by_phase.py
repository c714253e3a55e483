"""Control periods per flight by phase (``rocketmc.bench.periods_by_phase``, which ``rocketmc bench`` reports for its
campaign) for any campaign: the ascent (to apogee), periods of ``control_dt_s`` or less after apogee (canopy openings
and their settling, wind-layer crossings) and the long steady-descent periods; medians over 32 realizations.

    python benchmarks/steps_by_phase.py [--campaign campaigns/lynx_nominal.toml]
"""

from __future__ import annotations

import argparse
import json

from rocketmc.bench import periods_by_phase
from rocketmc.campaign import load_campaign


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--campaign", default="campaigns/lynx_nominal.toml")
    args = parser.parse_args()
    print(json.dumps(periods_by_phase(load_campaign(args.campaign)), indent=1))


if __name__ == "__main__":
    main()

"""The tuned guidance (a campaign written by `rocketmc tune`) against the thesis's and no controller, on held-out seeds.

For each base campaign (the nominal flight under drogue and main on perfect navigation, the ballistic flight, the
nominal flight on the full GNC with realistic sensor errors), three runs of the same N realizations of the campaign's
own seed (the tuning trained on seed + 1): controller off, the thesis's guidance, and the base campaign with the tuned
file's guidance numbers. Each set is compared as `rocketmc compare` does (paired: the same winds and gusts), the
result files written under --out.

    python benchmarks/tuned_controller.py [--tuned campaigns/lynx_nominal_ctrl_tuned.toml] [--n 10000] [--out results/tuned]
                                          [--bases lynx_nominal_ctrl_1s,lynx_ballistic_ctrl_1s,lynx_nominal_gnc_1s_realistic]
"""

from __future__ import annotations

import argparse
from pathlib import Path

from rocketmc.analysis import load_run
from rocketmc.analysis.compare import compare, format_comparison
from rocketmc.campaign import load_campaign, with_overrides
from rocketmc.campaign.model import GUIDANCE_NUMBERS
from rocketmc.campaign.run import run_campaign

CAMPAIGNS = Path(__file__).resolve().parents[1] / "campaigns"


def tuned_numbers(tuned_file: Path, base) -> dict[str, float]:
    """The guidance numbers of ``tuned_file`` that differ from ``base``'s (dotted paths), with its upwind aim."""
    tuned = load_campaign(tuned_file).config.gnc.guidance.model_dump()
    own = base.config.gnc.guidance.model_dump()
    values = {}
    for path in GUIDANCE_NUMBERS:
        name, _, index = path.removeprefix("gnc.guidance.").partition(".")
        value, before = (tuned[name], own[name]) if not index else (tuned[name][int(index)], own[name][int(index)])
        if value is not None and value != before:
            values[path] = value
    return values


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tuned", type=Path, default=CAMPAIGNS / "lynx_nominal_ctrl_tuned.toml")
    parser.add_argument("--n", type=int, default=10_000)
    parser.add_argument("--out", type=Path, default=Path("results/tuned"))
    parser.add_argument("--bases", default="lynx_nominal_ctrl_1s,lynx_ballistic_ctrl_1s,lynx_nominal_gnc_1s_realistic")
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    for name in args.bases.split(","):
        base = with_overrides(load_campaign(CAMPAIGNS / f"{name}.toml"), n_realizations=args.n)
        values = tuned_numbers(args.tuned, base)
        runs = {"off": with_overrides(base, controller=False), "thesis": base, "tuned": with_overrides(base, values=values)}
        files = []
        for label, campaign in runs.items():
            out = args.out / f"{name}_{label}.h5"
            run_campaign(campaign, out, force=True)
            files.append((str(out), load_run(out)))
        print(f"## {name}: controller off, the thesis's guidance, tuned ({values})")
        print(format_comparison(compare(files)), flush=True)


if __name__ == "__main__":
    main()

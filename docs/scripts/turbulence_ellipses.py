"""Impact ellipses of lynx_nominal and lynx_ballistic with and without Dryden turbulence.

    python docs/scripts/turbulence_ellipses.py [--n 1000] [--out docs/figures/turbulence_ellipses.png]

Each campaign is flown as written (thesis wind layers + turbulence severity drawn from
{0, 0, 0, 1, 1, 1, 2, 2, 3}) and again without the turbulence: same seed, so every other draw
(wind layers, mass, thrust, launch angles) is identical flight by flight. Prints the 95 % ellipses,
the spread of the apogee, the per-flight impact shift and the throughput of both runs.
"""

from __future__ import annotations

import argparse
import time
import tomllib
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from rocketmc.analysis import confidence_ellipse
from rocketmc.campaign import campaign_from_dict, run_chunks

CAMPAIGNS = ("campaigns/lynx_nominal.toml", "campaigns/lynx_ballistic.toml")


def fly(raw: dict, n: int) -> tuple[dict, float]:
    """Outputs of the campaign ``raw`` with N = n, and its flights per second after compilation."""
    campaign = campaign_from_dict({**raw, "n_realizations": n}, Path("campaigns"))
    runs = run_chunks(campaign, chunk_size=min(n, 1000))
    next(runs)  # compile time
    t0 = time.perf_counter()
    chunks = list(runs)
    rate = n / (time.perf_counter() - t0)
    return {k: np.concatenate([c.outputs[k] for c in chunks]) for k in chunks[0].outputs}, rate


def without_turbulence(raw: dict) -> dict:
    raw = {**raw, "environment": {k: v for k, v in raw["environment"].items() if k != "turbulence"}}
    raw["dispersions"] = {k: v for k, v in raw["dispersions"].items() if not k.startswith("environment.turbulence")}
    return raw


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=1000)
    parser.add_argument("--out", default="docs/figures/turbulence_ellipses.png")
    args = parser.parse_args()

    fig = Figure(figsize=(12, 6), layout="constrained")
    for ax, path in zip(fig.subplots(1, 2), CAMPAIGNS):
        raw = tomllib.loads(Path(path).read_text())
        results = {"with turbulence": fly(raw, args.n), "without": fly(without_turbulence(raw), args.n)}
        print(f"\n{raw['name']} (N = {args.n})")
        print(f"{'':>16} {'ok':>5} {'flights/s':>9} {'centre N, E [m]':>17} {'semi-axes [m]':>15} {'az [°]':>6} "
              f"{'area [km²]':>10} {'apogee σ [m]':>12}")  # fmt: skip
        for (label, (out, rate)), color in zip(results.items(), ("tab:red", "tab:blue")):
            ok = out["status"] == 0
            e = confidence_ellipse(out["impact_north_m"][ok], out["impact_east_m"][ok], 0.95)
            print(f"{label:>16} {ok.sum():>5} {rate:>9.0f} {e.center_north_m:>8.0f} {e.center_east_m:>8.0f} "
                  f"{e.semi_major_m:>7.0f} {e.semi_minor_m:>7.0f} {e.orientation_deg:>6.0f} {e.area_m2 / 1e6:>10.3f} "
                  f"{np.std(out['apogee_agl_m'][ok]):>12.1f}")  # fmt: skip
            ax.scatter(out["impact_east_m"][ok], out["impact_north_m"][ok], s=4, color=color, alpha=0.35, linewidths=0)
            b_north, b_east = e.boundary()
            ax.plot(b_east, b_north, color=color, linewidth=2, label=f"{label}: 95 % ellipse {e.area_m2 / 1e6:.2f} km²")
        (turb, _), (calm, _) = results.values()
        both = (turb["status"] == 0) & (calm["status"] == 0)
        shift = np.hypot(turb["impact_north_m"] - calm["impact_north_m"], turb["impact_east_m"] - calm["impact_east_m"])
        apogee_change = (turb["apogee_agl_m"] - calm["apogee_agl_m"])[both]
        print(f"impact shift of the same flight with turbulence: median {np.median(shift[both]):.0f} m, 95th "
              f"percentile {np.percentile(shift[both], 95):.0f} m; apogee change {np.mean(apogee_change):+.1f} m "
              f"mean, {np.std(apogee_change):.1f} m std")  # fmt: skip
        ax.plot(0.0, 0.0, "k^", markersize=9, label="pad")
        ax.set_title(f"{raw['name']}: impact points, N = {args.n}")
        ax.set_xlabel("east of pad [m]")
        ax.set_ylabel("north of pad [m]")
        ax.set_aspect("equal", adjustable="datalim")
        ax.grid(True, alpha=0.4)
        ax.legend(loc="best", fontsize="small")
    fig.savefig(args.out, dpi=130)
    print(f"\nwrote {args.out}")


if __name__ == "__main__":
    main()

"""The apogee against the air brakes' target: brakes off, on the true state, on the flight software's navigation, and
that navigation with a drag the software does not know or a noisier barometer; each on the campaign's law and, for a
campaign flying the apogee prediction, on the reference-trajectory PI too; realizations paired (same seed and draws),
the RMS error's ratio to the brakes off with a paired bootstrap interval.

    python benchmarks/airbrakes.py [--campaign campaigns/lynx_euroc_airbrakes.toml] [--n 10000] [--gnc-n 2000]
                                   [--only CASE ...]

The navigation cases fly ``campaigns/<name>_gnc.toml`` when it exists (the campaign's brakes on the MEKF and the
Kalman filter over realistic sensors), else they are left out. Writes nothing; prints one line per case and a JSON
dict at the end.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from rocketmc.campaign import load_campaign, run_chunks, with_overrides
from rocketmc.ellipse import percentile_interval

UNKNOWN_DRAG = {"dist": "normal", "mean": 1.1, "std": 0.05, "low": 0.8, "high": 1.4}
"""The airframe's drag 10 % above what the software knows (its nominal drag_scale 1), with the usual 5 % spread."""


def fly(campaign) -> dict:
    chunks = list(run_chunks(campaign))[1:]  # the first item is the compile time
    return {k: np.concatenate([c.outputs[k] for c in chunks]) for k in ("apogee_agl_m", "status",
                                                                        "airbrake_saturated_fraction")
            if k in chunks[0].outputs}  # fmt: skip


PI = {"airbrakes.controller": "reference_pi"}


def cases(path: Path, n: int, gnc_n: int) -> dict:
    base = load_campaign(path)
    other = base.config.airbrakes.controller == "prediction"
    runs = {"off": with_overrides(base, n_realizations=n, airbrakes=False), "truth": with_overrides(base, n_realizations=n)}
    runs |= {"truth, reference-trajectory PI": with_overrides(base, n_realizations=n, values=PI)} if other else {}
    gnc_path = path.with_name(f"{path.stem}_gnc.toml")
    if gnc_path.exists():
        gnc = with_overrides(load_campaign(gnc_path), n_realizations=gnc_n)
        if gnc_n != n:
            runs["off (N of the navigation cases)"] = with_overrides(base, n_realizations=gnc_n, airbrakes=False)
        runs |= {"navigation": gnc,
                 **({"navigation, reference-trajectory PI": with_overrides(gnc, values=PI)} if other else {}),
                 "navigation, drag +10 % unknown": with_overrides(gnc, values={"dispersions.rocket.aero.drag_scale": UNKNOWN_DRAG}),
                 "navigation, barometer noise 12 Pa": with_overrides(gnc, values={"avionics.barometer.noise_std": 12.0}),
                 "navigation, barometer noise 60 Pa": with_overrides(gnc, values={"avionics.barometer.noise_std": 60.0})}  # fmt: skip
    return runs


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--campaign", default="campaigns/lynx_euroc_airbrakes.toml")
    parser.add_argument("--n", type=int, default=10_000)
    parser.add_argument("--gnc-n", type=int, default=2_000)
    parser.add_argument("--only", action="append", metavar="CASE",
                        help="this case (its name as printed; repeat for more) and its brakes-off baseline")
    args = parser.parse_args()
    path = Path(args.campaign)
    target = load_campaign(path).config.airbrakes.target_apogee_m
    flown, report = {}, {"campaign": path.stem, "target_m": target}
    only = None if args.only is None else set(args.only)
    for name, campaign in cases(path, args.n, args.gnc_n).items():
        if only is not None and not name.startswith("off") and name not in only:
            continue
        out = flown[name] = fly(campaign)
        ok = out["status"] == 0
        error = out["apogee_agl_m"] - target
        baseline = flown["off"] if len(error) == args.n else flown["off (N of the navigation cases)"]
        both = ok & (baseline["status"] == 0)
        rms = lambda e, axis=-1: np.sqrt(np.mean(e**2, axis=axis))  # noqa: E731
        base_error = baseline["apogee_agl_m"][both] - target
        ratio = float(rms(error[both]) / rms(base_error))
        interval = percentile_interval((base_error, error[both]), lambda b, e, axis=-1: rms(e, axis) / rms(b, axis))
        row = {"n": len(error), "ok": int(ok.sum()), "mean_error_m": float(error[ok].mean()),
               "rms_error_m": float(rms(error[ok])), "interval_95_m": [float(x) for x in np.percentile(error[ok], [2.5, 97.5])],
               "within_1_percent": float(np.mean(np.abs(error[ok]) <= 0.01 * target)),
               "rms_ratio_to_off": ratio, "rms_ratio_interval": list(interval),
               "saturated_fraction_mean": float(np.nanmean(out["airbrake_saturated_fraction"][ok]))
               if "airbrake_saturated_fraction" in out else None}  # fmt: skip
        report[name] = row
        low, high = row["interval_95_m"]
        print(f"{name:36s} N {row['n']:6d} ok {row['ok']:6d}: mean error {row['mean_error_m']:+8.1f} m, RMS "
              f"{row['rms_error_m']:7.1f} m, 95 % {low:+7.1f}…{high:+7.1f} m, within 1 % {100 * row['within_1_percent']:5.1f} %, "
              f"RMS/off {ratio:.3f} ({interval[0]:.3f}…{interval[1]:.3f})", flush=True)  # fmt: skip
    print(json.dumps(report, indent=1))


if __name__ == "__main__":
    main()

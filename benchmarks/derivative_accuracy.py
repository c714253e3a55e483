"""Derivatives through the flight against central finite differences, over realizations of a campaign.

For each realization: the derivatives of the landing point, apogee and landing speed with respect to ``--wrt``
(``campaign.derivatives.sensitivities``: reverse mode, with its linearity check) and the central differences of the
same flights at x ± h·max(1, |x|). Per output, each realization's error is the largest |derivative − difference| over the
inputs relative to the output's largest derivative in that realization (the scale a share or a gradient step sees);
the median and the 90th percentile over the realizations, for all and for those the linearity check did not flag.

    python benchmarks/derivative_accuracy.py [--campaign campaigns/lynx_ballistic.toml] [--n 100] [--step 1e-6]
                                             [--wrt PATH,...]
"""

from __future__ import annotations

import argparse
import json

import jax
import jax.numpy as jnp
import numpy as np

from rocketmc.analysis.sensitivities import FLAG_MISMATCH
from rocketmc.campaign import load_campaign
from rocketmc.campaign.derivatives import DIFFERENTIATED_OUTPUTS, batch_function, sensitivities
from rocketmc.campaign.runner import sim_settings

WRT = ("rocket.motor.thrust_scale", "rocket.dry_mass_kg", "rocket.aero.drag_scale", "environment.wind.layers.0.speed_mps",
       "environment.wind.layers.1.from_deg", "environment.wind.layers.0.thickness_m", "launch.elevation_deg")  # fmt: skip


def measure(campaign, n: int, step: float, wrt: tuple[str, ...]) -> dict:
    settings, master = sim_settings(campaign), jax.random.key(campaign.config.seed)
    indices = jnp.arange(n, dtype=jnp.uint32)

    def differences(indices):
        k = len(wrt)
        x0, f = batch_function(campaign, settings, master, jnp.repeat(indices, 2 * k), wrt)
        h = step * jnp.maximum(1.0, jnp.abs(x0))
        moves = jnp.tile(jnp.concatenate([jnp.eye(k), -jnp.eye(k)]), (len(indices), 1))
        y = f(x0 + moves * h)[0].reshape(len(indices), 2, k, -1)  # flights, ±, inputs, outputs
        return ((y[:, 0] - y[:, 1]) / (2 * h[:: 2 * k, :, None])).transpose(0, 2, 1)  # flights, outputs, inputs

    _, status, derivatives, mismatch = jax.jit(lambda i: sensitivities(campaign, settings, master, i, wrt))(indices)
    status, derivatives, mismatch = map(np.asarray, (status, derivatives, mismatch))
    differences = np.asarray(jax.jit(differences)(indices))
    ok = status == 0
    report = {"campaign": campaign.config.name, "n": n, "ok": int(ok.sum()), "step": step, "wrt": list(wrt)}
    for k, name in enumerate(DIFFERENTIATED_OUTPUTS):
        scale = np.abs(differences[:, k]).max(axis=1)
        error = np.abs(derivatives[:, k] - differences[:, k]).max(axis=1) / np.where(scale > 0, scale, np.nan)
        flagged = mismatch[:, k] > FLAG_MISMATCH
        trusted = ok & ~flagged
        report[name] = {
            "median": float(np.nanmedian(error[ok])), "p90": float(np.nanpercentile(error[ok], 90)),
            "flagged": int((ok & flagged).sum()),
            "median_unflagged": float(np.nanmedian(error[trusted])), "p90_unflagged": float(np.nanpercentile(error[trusted], 90)),
            "worst_flagged": float(np.nanmax(error[ok & flagged])) if (ok & flagged).any() else None,
        }  # fmt: skip
    return report


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--campaign", default="campaigns/lynx_ballistic.toml")
    parser.add_argument("--n", type=int, default=100)
    parser.add_argument("--step", type=float, default=1e-6)
    parser.add_argument("--wrt", help="inputs (dotted paths), comma-separated")
    args = parser.parse_args()
    wrt = WRT if args.wrt is None else tuple(args.wrt.split(","))
    report = measure(load_campaign(args.campaign), args.n, args.step, wrt)
    print(json.dumps(report, indent=1))
    for name in DIFFERENTIATED_OUTPUTS:
        r = report[name]
        print(f"{name:<18} error median {100 * r['median']:.3g} %, 90th percentile {100 * r['p90']:.3g} %; "
              f"{r['flagged']} flagged; unflagged: median {100 * r['median_unflagged']:.3g} %, "
              f"90th {100 * r['p90_unflagged']:.3g} %")  # fmt: skip


if __name__ == "__main__":
    main()

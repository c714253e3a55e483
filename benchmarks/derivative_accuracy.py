"""Derivatives through the flight against central finite differences, over realizations of a campaign.

For each realization: the derivatives of the landing point, apogee and landing speed with respect to ``--wrt``
(``campaign.derivatives.sensitivities``: reverse mode, with its linearity check) and the central differences of the
same flights at x ± h·max(1, |x|). Per output, each realization's error is the largest |derivative − difference| over the
inputs relative to the output's largest derivative in that realization (the scale a share or a gradient step sees);
the median and the 90th percentile over the realizations, for all and for those the linearity check did not flag.

    python benchmarks/derivative_accuracy.py [--campaign campaigns/lynx_ballistic.toml] [--n 100] [--step 1e-6]
                                             [--wrt PATH,...] [--chunk 25]
    python benchmarks/derivative_accuracy.py --campaign C --scan 0 [--wrt PATH]

``--scan R``: realization R's central differences with respect to the first of ``--wrt`` at relative steps from 10⁻²
down to 10⁻⁶, one line per step, beside its reverse-mode derivative: whether the differences settle (a smooth flight)
or scatter at every scale (a flight with jumps below any step: the full GNC's landing point).

The realizations go through in chunks of ``--chunk`` (one compiled program, reused): the full GNC's reverse-mode program
over 100 flights plus its 1 400 difference flights holds ~10 GB at once, a chunk of 25 a quarter of it.
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


def measure(campaign, n: int, step: float, wrt: tuple[str, ...], chunk: int) -> dict:
    settings, master = sim_settings(campaign), jax.random.key(campaign.config.seed)
    k = len(wrt)

    def differences(indices):
        x0, f = batch_function(campaign, settings, master, jnp.repeat(indices, 2 * k), wrt)
        h = step * jnp.maximum(1.0, jnp.abs(x0))
        moves = jnp.tile(jnp.concatenate([jnp.eye(k), -jnp.eye(k)]), (len(indices), 1))
        y = f(x0 + moves * h)[0].reshape(len(indices), 2, k, -1)  # flights, ±, inputs, outputs
        return ((y[:, 0] - y[:, 1]) / (2 * h[:: 2 * k, :, None])).transpose(0, 2, 1)  # flights, outputs, inputs

    reverse = jax.jit(lambda indices: sensitivities(campaign, settings, master, indices, wrt)[1:])
    differences = jax.jit(differences)
    parts = []
    for first in range(0, n, chunk):
        indices = jnp.arange(first, first + chunk, dtype=jnp.uint32)
        parts.append([np.asarray(a) for a in (*reverse(indices), differences(indices))])
        print(f"realizations {first}..{first + chunk - 1} done", flush=True)
    status, derivatives, mismatch, differences = (np.concatenate(a)[:n] for a in zip(*parts))
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


SCAN_STEPS = (1e-2, 3e-3, 1e-3, 3e-4, 1e-4, 3e-5, 1e-5, 1e-6)


def scan(campaign, realization: int, path: str) -> None:
    settings, master = sim_settings(campaign), jax.random.key(campaign.config.seed)
    index = jnp.full((1,), realization, dtype=jnp.uint32)
    derivative = np.asarray(jax.jit(lambda i: sensitivities(campaign, settings, master, i, (path,))[2])(index))[0, :, 0]
    steps = np.array(SCAN_STEPS)
    x0, f = batch_function(campaign, settings, master, jnp.repeat(index, 2 * len(steps)), (path,))
    h = np.concatenate([steps, -steps]) * max(1.0, abs(float(x0[0, 0])))
    y = np.asarray(jax.jit(f)(x0 + h[:, None])[0])
    print(f"realization {realization}, d/d {path}: " + ", ".join(DIFFERENTIATED_OUTPUTS))
    print(f"{'reverse mode':>14s} " + " ".join(f"{d:12.4g}" for d in derivative))
    for k, step in enumerate(steps):
        difference = (y[k] - y[len(steps) + k]) / (2 * h[k])
        print(f"{f'step {step:.0e}':>14s} " + " ".join(f"{d:12.4g}" for d in difference))


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--campaign", default="campaigns/lynx_ballistic.toml")
    parser.add_argument("--n", type=int, default=100)
    parser.add_argument("--step", type=float, default=1e-6)
    parser.add_argument("--wrt", help="inputs (dotted paths), comma-separated")
    parser.add_argument("--chunk", type=int, default=25, help="realizations per compiled batch")
    parser.add_argument("--scan", type=int, metavar="R", help="realization R's differences at steps 1e-2 … 1e-6")
    args = parser.parse_args()
    wrt = WRT if args.wrt is None else tuple(args.wrt.split(","))
    if args.scan is not None:
        return scan(load_campaign(args.campaign), args.scan, wrt[0])
    report = measure(load_campaign(args.campaign), args.n, args.step, wrt, min(args.chunk, args.n))
    print(json.dumps(report, indent=1))
    for name in DIFFERENTIATED_OUTPUTS:
        r = report[name]
        print(f"{name:<18} error median {100 * r['median']:.3g} %, 90th percentile {100 * r['p90']:.3g} %; "
              f"{r['flagged']} flagged; unflagged: median {100 * r['median_unflagged']:.3g} %, "
              f"90th {100 * r['p90_unflagged']:.3g} %")  # fmt: skip


if __name__ == "__main__":
    main()

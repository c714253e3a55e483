"""Derivatives of a realization's outputs with respect to its inputs: the flight differentiated as one function.

A realization's inputs are its values (``Campaign.nominal`` with its draws, ``runner.realization_params``): the
derivatives are taken with respect to some of them, ``wrt`` (dotted paths: dispersed inputs, or design numbers the
compiled flight reads as arguments), at the values the realization flies, with its gusts and sensor errors held
(they are drawn from its key, not from the values). Forward mode (``jax.jacfwd``) goes through the flight's
``while_loop`` (``sim.flight.simulate_one``); reverse mode (``jax.jacrev``) through ``simulate_bounded``'s scan of a
fixed number of blocks. Both are per realization: their callers ``vmap`` and ``jit`` them.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import jax
import jax.numpy as jnp

from ..sim.flight import simulate_bounded, simulate_one
from ..sim.params import SimSettings
from .errors import ConfigError
from .limits import fixed_reason
from .model import flight_params
from .record import Campaign
from .sampling import realization_key, sample_dispersions, sample_faults

DIFFERENTIATED_OUTPUTS = ("impact_north_m", "impact_east_m", "apogee_agl_m", "impact_speed_mps")
"""The outputs whose derivatives are taken: where the flight lands, how high it goes and how fast it comes down."""


def differentiable_inputs(campaign: Campaign) -> list[str]:
    """The paths derivatives can be taken with respect to: every number of ``Campaign.nominal`` the flight reads
    from its values (``limits.fixed_reason`` None), the dispersed ones first."""
    dispersed = [path for path in campaign.config.dispersions if fixed_reason(path) is None]
    return dispersed + [path for path in campaign.nominal if path not in dispersed and fixed_reason(path) is None]


def check_inputs(campaign: Campaign, wrt: Sequence[str]) -> None:
    """Raise ``ConfigError`` naming the first of ``wrt`` that is not a differentiable input, and why."""
    allowed = set(differentiable_inputs(campaign))
    for path in wrt:
        if path in allowed:
            continue
        reason = fixed_reason(path) or "not a number of this campaign"
        raise ConfigError(f"--wrt {path}: {reason}")


def realization_function(campaign: Campaign, settings: SimSettings, master_key, index, wrt: Sequence[str],
                         n_blocks: int | None = None) -> tuple[jnp.ndarray, Callable]:  # fmt: skip
    """(x0, f): realization ``index``'s values of ``wrt`` (len(wrt),) and f(x) -> its ``DIFFERENTIATED_OUTPUTS``
    (len,) flown with those values set to x, everything else (draws, gusts, sensor errors) as it flies them.
    ``n_blocks``: fly ``simulate_bounded`` with that many blocks (reverse mode), else ``simulate_one``."""
    key = realization_key(master_key, index)
    values = {**campaign.nominal, **sample_dispersions(campaign, key), **sample_faults(campaign.config.faults, key)}
    x0 = jnp.stack([jnp.asarray(values[path], dtype=float) for path in wrt])

    def outputs(x):
        p = flight_params(campaign, {**values, **dict(zip(wrt, x))}, key)
        summary, _ = simulate_one(p, settings) if n_blocks is None else simulate_bounded(p, settings, n_blocks)
        return jnp.stack([summary[name] for name in DIFFERENTIATED_OUTPUTS])

    return x0, outputs


def jacobian(campaign: Campaign, settings: SimSettings, master_key, index, wrt: Sequence[str],
             n_blocks: int | None = None) -> tuple[jnp.ndarray, jnp.ndarray]:  # fmt: skip
    """Realization ``index``'s outputs (``DIFFERENTIATED_OUTPUTS``) and their derivatives (outputs, len(wrt)) with
    respect to ``wrt``: forward mode, or reverse mode through ``n_blocks`` blocks (``realization_function``)."""
    x0, f = realization_function(campaign, settings, master_key, index, wrt, n_blocks)
    if n_blocks is None:
        y, pushed = jax.vmap(lambda dx: jax.jvp(f, (x0,), (dx,)), out_axes=(None, 1))(jnp.eye(len(wrt)))
        return y, pushed
    y, pull = jax.vjp(f, x0)
    return y, jax.vmap(pull)(jnp.eye(len(DIFFERENTIATED_OUTPUTS)))[0]

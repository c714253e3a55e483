"""Derivatives of a realization's outputs with respect to its inputs: the flight differentiated as one function.

A realization's inputs are its values (``Campaign.nominal`` with its draws, ``runner.realization_params``): the
derivatives are taken with respect to some of them, ``wrt`` (dotted paths: dispersed inputs, or design numbers the
compiled flight reads as arguments), at the values the realization flies, with its gusts and sensor errors held
(they are drawn from its key, not from the values). Forward mode goes through the flight's ``while_loop``
(``sim.flight.simulate_one``: ``realization_function``, one flight); reverse mode through ``simulate_bounded``'s scan
of a fixed number of blocks (``batch_function``, ``jacobians``: a batch of flights). Their callers ``jit`` them
(``runner.chunk_function`` for ``rocketmc sensitivities``).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence

import jax
import jax.numpy as jnp
import numpy as np

from ..math import safe_sqrt
from ..sim.flight import max_blocks, simulate_bounded, simulate_one
from ..sim.params import FlightParams, SimSettings
from .errors import ConfigError
from .limits import fixed_reason
from .model import AIRBRAKE_NUMBERS, GUIDANCE_NUMBERS, airbrake_numbers, flight_params, with_airbrakes, with_guidance
from .record import Campaign
from .sampling import realization_key, sample_dispersions, sample_faults

DIFFERENTIATED_OUTPUTS = ("impact_north_m", "impact_east_m", "apogee_agl_m", "impact_speed_mps")
"""The outputs whose derivatives are taken: where the flight lands, how high it goes and how fast it comes down."""


def differentiable_inputs(campaign: Campaign) -> list[str]:
    """The paths derivatives can be taken with respect to: every number of ``Campaign.nominal`` the flight reads
    from its values (``limits.fixed_reason`` None), the dispersed ones first, then the guidance's numbers
    (``model.GUIDANCE_NUMBERS``) of a campaign with a closed loop and the air brakes' gains (``model.airbrake_numbers``)."""
    dispersed = [path for path in campaign.config.dispersions if fixed_reason(path) is None]
    guidance = [path for path in GUIDANCE_NUMBERS if campaign.config.gnc is not None and path in campaign.nominal]
    undispersed = [path for path in campaign.nominal if path not in dispersed and fixed_reason(path) is None]
    return dispersed + undispersed + guidance + list(airbrake_numbers(campaign))


def _flight_params(campaign: Campaign, values: Mapping, key, wrt: Sequence[str], x) -> FlightParams:
    """The flight of ``values`` with those of ``wrt`` set to ``x``: guidance numbers in its guidance
    (``with_guidance``), the air brakes' gains in its brakes (``with_airbrakes``), the others among its values."""
    given = dict(zip(wrt, x))
    params = flight_params(campaign, {**values, **given}, key)
    guidance = {path: value for path, value in given.items() if path in GUIDANCE_NUMBERS}
    brakes = {path: value for path, value in given.items() if path in AIRBRAKE_NUMBERS}
    params = with_guidance(params, guidance) if guidance else params
    return with_airbrakes(params, brakes) if brakes else params


def default_inputs(campaign: Campaign) -> list[str]:
    """The inputs ``rocketmc sensitivities`` differentiates by default: the dispersed ones drawn from a continuous
    distribution (a choice between values is discrete: no derivative describes it)."""
    dispersions = campaign.config.dispersions
    return [path for path in differentiable_inputs(campaign) if path in dispersions and dispersions[path].dist != "choice"]


def check_inputs(campaign: Campaign, wrt: Sequence[str]) -> None:
    """Raise ``ConfigError`` naming the first of ``wrt`` that is not a differentiable input, and why."""
    allowed = set(differentiable_inputs(campaign))
    for path in wrt:
        if path in allowed:
            continue
        reason = fixed_reason(path) or "not a number of this campaign"
        raise ConfigError(f"--wrt {path}: {reason}")


def spread(dispersion: Mapping | None) -> float:
    """The standard deviation of a dispersed input [its unit] from its dispersion's fields (a ``[dispersions]`` entry
    as a dict): a normal's std (its clipping ignored), a uniform's (high − low)/√12, a choice's weighted std of its
    values; 0 for an input not dispersed (None)."""
    if dispersion is None:
        return 0.0
    if dispersion["dist"] == "normal":
        return float(dispersion["std"])
    if dispersion["dist"] == "uniform":
        return float((dispersion["high"] - dispersion["low"]) / np.sqrt(12.0))
    values = np.asarray(dispersion["values"], dtype=float)
    weights = np.ones(len(values)) if dispersion.get("weights") is None else np.asarray(dispersion["weights"], dtype=float)
    return float(np.sqrt(np.cov(values, aweights=weights, bias=True)))


def _values(campaign: Campaign, master_key, index) -> tuple[dict, jnp.ndarray]:
    """Realization ``index``'s values (``Campaign.nominal`` and the brakes' gains, with its draws) and key."""
    key = realization_key(master_key, index)
    drawn = {**sample_dispersions(campaign, key), **sample_faults(campaign.config.faults, key)}
    return {**campaign.nominal, **airbrake_numbers(campaign), **drawn}, key


def _outputs(summary: dict) -> jnp.ndarray:
    return jnp.stack([summary[name] for name in DIFFERENTIATED_OUTPUTS], axis=-1)


def realization_function(campaign: Campaign, settings: SimSettings, master_key, index,
                         wrt: Sequence[str]) -> tuple[jnp.ndarray, Callable]:  # fmt: skip
    """(x0, f): realization ``index``'s values of ``wrt`` (len(wrt),) and f(x) -> (its ``DIFFERENTIATED_OUTPUTS``
    (len,), (summary, status)) flown with those values set to x, everything else (draws, gusts, sensor errors) as
    it flies them, by ``simulate_one`` (its ``while_loop``: forward mode)."""
    values, key = _values(campaign, master_key, index)

    def outputs(x):
        summary, status = simulate_one(_flight_params(campaign, values, key, wrt, x), settings)
        return _outputs(summary), (summary, status)

    return jnp.stack([jnp.asarray(values[path], dtype=float) for path in wrt]), outputs


def batch_function(campaign: Campaign, settings: SimSettings, master_key, indices, wrt: Sequence[str],
                   reverse: bool = False) -> tuple[jnp.ndarray, Callable]:  # fmt: skip
    """``realization_function`` for the realizations ``indices``: x0 (flights, len(wrt)) and f(x) -> (outputs
    (flights, len), (summaries, statuses)), each flight flown with its row of x; reverse: flown by
    ``simulate_bounded`` (``max_blocks``), else by ``simulate_one`` vmapped."""
    values, keys = jax.vmap(lambda i: _values(campaign, master_key, i))(indices)

    def params(flight):  # built inside the vmapped flights: what they share stays one array
        v, key, x = flight
        return _flight_params(campaign, v, key, wrt, x)

    def outputs(x):
        if reverse:
            summary, status = simulate_bounded(params, (values, keys, x), settings, max_blocks(settings))
        else:
            summary, status = jax.vmap(lambda flight: simulate_one(params(flight), settings))((values, keys, x))
        return _outputs(summary), (summary, status)

    return jnp.stack([jnp.asarray(values[path], dtype=float) for path in wrt], axis=1), outputs


def jacobians(campaign: Campaign, settings: SimSettings, master_key, indices,
              wrt: Sequence[str]) -> tuple[dict, jnp.ndarray, jnp.ndarray]:  # fmt: skip
    """The realizations ``indices``' (summaries, statuses, derivatives (flights, len(DIFFERENTIATED_OUTPUTS),
    len(wrt))) with respect to their values of ``wrt``: reverse mode, one backward pass per output (the flights are
    independent, so a cotangent of ones on one output gives every flight's row of that output)."""
    x0, f = batch_function(campaign, settings, master_key, indices, wrt, reverse=True)
    outputs, pull, (summary, status) = jax.vjp(f, x0, has_aux=True)
    rows = [pull(jnp.zeros_like(outputs).at[:, k].set(1.0))[0] for k in range(len(DIFFERENTIATED_OUTPUTS))]
    return summary, status, jnp.stack(rows, axis=1)


MISMATCH = "mismatch"
"""The name of the linearity check's mismatch (``sensitivities``) beside the derivatives in a result file."""
LINEARITY_STEP = 0.01
"""The linearity check's step: each dispersed input moved by this fraction of its spread (``spread``)."""


def sensitivities(campaign: Campaign, settings: SimSettings, master_key, indices, wrt: Sequence[str]) -> tuple:
    """The realizations ``indices``' (summaries, statuses, derivatives, mismatch): ``jacobians``', and for each flight
    and output the linearity check's mismatch (flights, len(DIFFERENTIATED_OUTPUTS)): the flights at x0 ± d, each
    dispersed input of ``wrt`` moved by ``LINEARITY_STEP`` of its spread with alternating signs, their half
    difference against the derivatives' prediction J·d, |½(f(x0 + d) − f(x0 − d)) − J·d| / √Σ(J_k d_k)² (the size
    J·d has for steps of random signs: large terms that cancel in J·d do not hide a failed prediction). Near 0 where
    the flight is smooth over the step; of order 1 where a discontinuity lies within it (a deployment crossing a
    wind layer's boundary, a servo saturating, a GNC tick's decision changing) or where the flight amplifies every
    change (a chaotic descent), where the derivatives are not to be trusted."""
    summary, status, derivatives = jacobians(campaign, settings, master_key, indices, wrt)
    x0, f = batch_function(campaign, settings, master_key, jnp.concatenate([indices, indices]), wrt)
    x0 = x0[: len(indices)]
    signs = np.where(np.arange(len(wrt)) % 2 == 0, 1.0, -1.0)
    dispersions = campaign.config.dispersions
    spreads = [spread(dispersions[path].model_dump() if path in dispersions else None) for path in wrt]
    step = jnp.asarray(LINEARITY_STEP * signs * np.array(spreads))
    moved = f(jnp.concatenate([x0 + step[None, :], x0 - step[None, :]]))[0]
    contributions = derivatives * step[None, None, :]
    half = 0.5 * (moved[: len(x0)] - moved[len(x0) :])
    mismatch = jnp.abs(half - contributions.sum(axis=2))
    return summary, status, derivatives, mismatch / jnp.maximum(safe_sqrt((contributions**2).sum(axis=2)), 1e-300)


def ellipse_area_m2(outputs, status, level_scale: float):
    """The landing points' ellipse area π·k²·√det Σ [m²] over the ok flights (status 0) of ``outputs`` (flights,
    len(DIFFERENTIATED_OUTPUTS)), Σ their covariance (ddof = 1), k² = ``level_scale`` (``ellipse.chi2_scale``):
    ``ellipse.ellipse_area_m2`` with the failed flights weighted 0, differentiable."""
    ok = (status == 0) & jnp.all(jnp.isfinite(outputs[:, :2]), axis=1)
    n = ok.sum().astype(outputs.dtype)
    weight = ok.astype(outputs.dtype) / jnp.maximum(n, 2.0)
    points = jnp.where(ok[:, None], outputs[:, :2], 0.0)
    centred = jnp.where(ok[:, None], points - (weight[:, None] * points).sum(axis=0, keepdims=True), 0.0)
    covariance = jnp.einsum("f,fi,fj->ij", weight, centred, centred) * n / jnp.maximum(n - 1.0, 1.0)
    return jnp.pi * level_scale * safe_sqrt(jnp.maximum(jnp.linalg.det(covariance), 0.0))

"""Canard servos: one first-order lag per fin, its command sampled and held at the GNC rate.

Fins are numbered as in ``aero.canards`` (δ1..δ4: panel 1 up, 2 starboard, 3 down, 4 port), positive
as in docs/conventions.md; every per-fin quantity is an (n,) array in that order, the shape the
aerodynamics takes. Over a control period of length T, from its start t_k, with the command held:

    δ(s) = δ_cmd + (δ_k − δ_cmd)·exp(−s/τ),   0 ≤ s ≤ T,

the exact solution of τ·dδ/dt = δ_cmd − δ, smooth inside the period: the right-hand side evaluates it
at each RK4 stage time and RK4 keeps its order (no stiff servo state in the integrator).

At a period start (``hold_command``) the command is clipped to ±limit, then, with a rate limit, the
step δ_cmd − δ_k to ±rate·τ (as clip(δ_cmd, δ_k − rate·τ, δ_k + rate·τ): a command within reach is held
bit for bit). Both clip the *command*, which stays between δ_k and the clipped command: the output
moves monotonically from δ_k toward δ_cmd, so with |δ_k| ≤ limit it never leaves ±limit, bitwise (the
sign of (δ_k − δ_cmd)·exp(−s/τ) is exact and rounding to nearest is monotone). Chained periods approach
a saturated command to within n ulp from inside, n·(1 − exp(−T/τ)) < ½ (2 ulp, 6e-17 rad, at 50 Hz).

The rate limit is a slew-rate bound: |dδ/dt| = |δ_cmd − δ_k|·exp(−s/τ)/τ is largest at the period's
start, so a step of at most rate·τ keeps |dδ/dt| ≤ rate at every instant, with δ(s) still the smooth
exponential RK4 relies on (a ramp-then-exponential slew would put a kink inside the period).

The per-fin offset (rigging error, the panel's mechanical zero) adds to the output after the limit: it
is not part of the servo state and is not clipped.
"""

from __future__ import annotations

import jax.numpy as jnp

from ..pytree import pytree_dataclass


@pytree_dataclass
class ServoParams:
    """time_constant_s: first-order time constant τ [s] (scalar or per fin); limit_rad: deflection
    limit, |δ_cmd| ≤ limit [rad]; offset_rad: per-fin offset added to the output, (n,) [rad];
    rate_limit_rad_s: bound on the deflection rate |dδ/dt| [rad/s] (the step |δ_cmd − δ_k| ≤ rate·τ), or None
    for none (a static choice: the pytree's structure, so changing it recompiles)."""

    time_constant_s: jnp.ndarray
    limit_rad: jnp.ndarray
    offset_rad: jnp.ndarray
    rate_limit_rad_s: jnp.ndarray | None = None


@pytree_dataclass
class ServoState:
    """deflection_rad: δ_k, each fin's deflection at the start of the period, without the offset, (n,)
    [rad]; command_rad: δ_cmd, the command held over the period (after the limits), (n,) [rad]."""

    deflection_rad: jnp.ndarray
    command_rad: jnp.ndarray


def hold_command(params: ServoParams, state: ServoState, command) -> ServoState:
    """The state at a period start with ``command`` (n,) [rad] sampled and held: clipped to ±limit,
    then its step from δ_k clipped to ±rate·τ if there is a rate limit (|dδ/dt| ≤ rate then)."""
    held = jnp.clip(command, -params.limit_rad, params.limit_rad)
    if params.rate_limit_rad_s is not None:
        max_step = params.rate_limit_rad_s * params.time_constant_s
        held = jnp.clip(held, state.deflection_rad - max_step, state.deflection_rad + max_step)
    return ServoState(state.deflection_rad, held)


def _lag(params: ServoParams, state: ServoState, s):
    """δ(s) without the offset [rad], s [s] into the period."""
    return state.command_rad + (state.deflection_rad - state.command_rad) * jnp.exp(-s / params.time_constant_s)


def deflection_at(params: ServoParams, state: ServoState, s):
    """Each fin's deflection (n,) [rad] ``s`` seconds into the period (0 ≤ s ≤ T), the offset included:
    what the aerodynamics sees at an RK4 stage time."""
    return _lag(params, state, s) + params.offset_rad


def end_of_period(params: ServoParams, state: ServoState, period_s) -> ServoState:
    """The state after a period of ``period_s`` [s]: δ_k+1 = δ(period_s) without the offset, the
    command still held (``hold_command`` replaces it at the next period start)."""
    return ServoState(_lag(params, state, period_s), state.command_rad)

"""Error primitives of a sensor channel: what a measurement adds to the truth, sample by sample.

A channel of n axes (a 3-axis accelerometer, a barometer's one, four canard encoders) measures, at each
of its samples, in its own unit (SI) and frame:

    y = Q(S(G·x + b + β_k + σ·η_k)),   β_k = β_{k−1} + σ_β·ζ_k,   η_k, ζ_k ~ N(0, I)

x the truth, G the gain matrix (scale factor, cross-axis coupling and misalignment: unknown to the
avionics), b the constant bias (drawn per flight), β the bias instability as a random walk, σ the white
noise per sample (the sensor's and the airframe's vibration, σ² = σ_0² + (v·q̄)²), S saturation at the
range, Q quantisation to the LSB (round half away from zero).
The channel samples every ``every`` GNC ticks (sample-and-hold between) and delivers each sample
``delay`` ticks later. ``docs/sensors.md`` gives each sensor's model and sources.

Pure, single-vehicle, written by components (no small-matrix products under vmap: docs/sharp-bits.md).
"""

from __future__ import annotations

import jax
import jax.numpy as jnp

from ..math import safe_sqrt
from ..pytree import pytree_dataclass, static_field


def noise_per_sample(density, rate_hz):
    """White noise per sample [unit] of a density [unit/√Hz] sampled at ``rate_hz``: the Allan deviation
    at τ = 1 s equals the density (the datasheet convention, ARW [unit·√s] = density)."""
    return density * rate_hz**0.5


def walk_per_sample(density, rate_hz):
    """Step [unit] of a rate random walk of density K [unit/√s] at each sample at ``rate_hz``: the Allan
    deviation is K·√(τ/3)."""
    return density / rate_hz**0.5


def saturate(x, low, high):
    """``x`` clipped to the range [low, high]."""
    return jnp.clip(x, low, high)


@jax.custom_jvp
def quantize(x, lsb):
    """``x`` rounded to a multiple of ``lsb`` [unit], half away from zero; unchanged where lsb is 0. Its derivative
    in ``x`` is 1 (straight through: the mean slope of the staircase, which a change of many LSBs sees), not the
    staircase's 0 almost everywhere, so that a flight's derivatives see what the sensors see."""
    step = jnp.where(lsb > 0.0, lsb, 1.0)
    return jnp.where(lsb > 0.0, jnp.sign(x) * jnp.floor(jnp.abs(x) / step + 0.5) * step, x)


@quantize.defjvp
def _quantize_jvp(primals, tangents):
    (x, lsb), (dx, _) = primals, tangents
    return quantize(x, lsb), dx


@pytree_dataclass
class Channel:
    """The errors of an n-axis channel, in its unit (SI) and frame.

    gain: G (n, n), None for the identity; bias: b (n,); noise_std: σ per sample (scalar or (n,)), None for
    no white noise; walk_std: σ_β, the random walk's step per sample, None for no walk (None: nothing drawn for
    it, where a campaign's value is 0 and not dispersed); low, high: the range; lsb: the quantisation step
    (0: none); vibration: the airframe's, more white noise per sample per pascal of dynamic pressure (n,)
    [unit/Pa], its variance added to σ² (None: none). every: the sample period in GNC ticks; delay: the
    latency in ticks (both static); ideal: errors off (the truth at each sample, on the same schedule; static)."""

    gain: jnp.ndarray | None
    bias: jnp.ndarray
    noise_std: jnp.ndarray | None
    walk_std: jnp.ndarray | None
    low: jnp.ndarray
    high: jnp.ndarray
    lsb: jnp.ndarray
    vibration: jnp.ndarray | None = None
    every: int = static_field(default=1)
    delay: int = static_field(default=0)
    ideal: bool = static_field(default=False)

    @property
    def n(self) -> int:
        return self.bias.shape[-1]

    @property
    def noise_per_tick(self) -> int:
        """Standard normals a tick draws: white noise and walk step per axis (none when ideal or zero)."""
        white = self.noise_std is not None or self.vibration is not None
        return 0 if self.ideal else self.n * (white + (self.walk_std is not None))


@pytree_dataclass
class ChannelState:
    """walk: β (n,); queue: the samples not yet delivered, oldest first (delay, n), with their flags
    queued (delay,): a sample was taken at that tick."""

    walk: jnp.ndarray
    queue: jnp.ndarray
    queued: jnp.ndarray


def initial_channel(channel: Channel, like) -> ChannelState:
    """No walk yet, nothing queued; ``like``: a scalar of the flight's dtype."""
    zeros = jnp.zeros(channel.n, dtype=jnp.result_type(like))
    return ChannelState(zeros, jnp.zeros((channel.delay, channel.n), zeros.dtype), jnp.zeros(channel.delay, bool))


def white_std(channel: Channel, qbar):
    """The white noise per sample at dynamic pressure ``qbar`` [Pa]: the sensor's and the vibration's, independent
    (their variances add), or None without either."""
    if channel.vibration is None:
        return channel.noise_std
    shaking = channel.vibration * qbar
    return shaking if channel.noise_std is None else safe_sqrt(channel.noise_std**2 + shaking**2)


def corrupt(channel: Channel, truth, walk, noise, qbar=0.0):
    """(the measurement of ``truth`` (n,), the walk after this sample): ``noise`` the sample's
    ``noise_per_tick`` standard normals (white, then walk), ``walk`` β before it, ``qbar`` the dynamic
    pressure [Pa] (vibration)."""
    if channel.ideal:
        return truth, walk
    n, g = channel.n, channel.gain
    sigma = white_std(channel, qbar)
    if channel.walk_std is not None:
        walk = walk + channel.walk_std * noise[n * (sigma is not None) :]
    sensed = truth if g is None else jnp.stack([sum(g[i, j] * truth[j] for j in range(n)) for i in range(n)])
    y = sensed + channel.bias + walk
    if sigma is not None:
        y = y + sigma * noise[:n]
    return quantize(saturate(y, channel.low, channel.high), channel.lsb), walk


def sample(channel: Channel, state: ChannelState, tick, truth, noise, enabled=True, qbar=0.0):
    """The channel at GNC tick ``tick``: (delivered, fresh, new state). A sample is taken when ``tick`` is a
    multiple of ``every`` and ``enabled`` (the walk steps only then); ``fresh``: a sample taken ``delay``
    ticks ago is delivered now (``delivered``, else meaningless: hold the last one); qbar: the dynamic
    pressure [Pa] (vibration)."""
    due = (tick % channel.every == 0) & enabled
    measured, walk = corrupt(channel, truth, state.walk, noise, qbar)
    walk = jnp.where(due, walk, state.walk)
    if channel.delay == 0:
        return measured, due, ChannelState(walk, state.queue, state.queued)
    queue = jnp.concatenate([state.queue[1:], measured[None]])
    queued = jnp.concatenate([state.queued[1:], due[None]])
    return state.queue[0], state.queued[0], ChannelState(walk, queue, queued)

"""The canard servo's closed form: step response, chaining, saturation, sample-and-hold, rate limit,
offset, and jit/vmap bit-identity."""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np

from rocketmc.dynamics.servo import ServoParams, ServoState, deflection_at, end_of_period, hold_command

TAU = 0.0769  # s, the thesis's servo
T = 0.02  # s, the 50 Hz GNC period
LIMIT = float(np.deg2rad(10.0))
STAGES = (0.0, 0.25 * T, 0.5 * T, 0.75 * T)  # times inside a period, RK4's 0, T/2 among them
ZERO4 = np.zeros(4)


def servo(tau=TAU, rate=None, offset=ZERO4):
    return ServoParams(jnp.asarray(tau), jnp.asarray(LIMIT), jnp.asarray(offset), rate)


def at_rest(deflection=ZERO4):
    return ServoState(jnp.asarray(deflection, dtype=float), jnp.asarray(deflection, dtype=float))


def fly(params, command, periods, start=ZERO4, times=STAGES):
    """Deflections at ``times`` in each of ``periods`` periods, ``command(k)`` held over period k, and
    the end state; (periods, len(times), 4) [rad]."""
    state, rows = at_rest(start), []
    for k in range(periods):
        state = hold_command(params, state, jnp.asarray(command(k), dtype=float))
        rows.append([np.asarray(deflection_at(params, state, s)) for s in times])
        state = end_of_period(params, state, T)
    return np.asarray(rows), state


def test_step_response_is_the_exponential_at_every_sample():
    command = np.array([0.1, -0.05, 0.02, LIMIT])
    params = servo()
    inside, _ = fly(params, lambda k: command, 50, times=STAGES + (T,))
    t = np.arange(50)[:, None] * T + np.asarray(STAGES + (T,))[None, :]
    expected = command * (1.0 - np.exp(-t / TAU))[..., None]
    # Each period start rounds δ_k by ~1 ulp (1e-17 of 0.1 rad); the error is then carried times
    # exp(−T/τ) = 0.77 per period, so the chain stays within ~4 ulp; the reference rounds t and exp
    # itself. 1e-15 (~50 ulp of 0.17 rad) is that with margin; a τ wrong by 1e-9 relative would fail.
    np.testing.assert_allclose(inside, expected, rtol=0, atol=1e-15)


def test_chained_periods_are_one_long_exponential():
    params = servo()
    state = hold_command(params, at_rest([0.1, -0.1, 0.05, 0.0]), jnp.array([-0.15, 0.15, 0.0, 0.1]))
    chained = state
    for _ in range(50):
        chained = end_of_period(params, chained, T)
    once = end_of_period(params, state, 50 * T)
    # exp(a)·exp(b) = exp(a + b) up to rounding; 50 roundings of ~1e-17 rad each, damped per period.
    np.testing.assert_allclose(np.asarray(chained.deflection_rad), np.asarray(once.deflection_rad), rtol=0, atol=1e-12)


def test_saturation_holds_the_limit_exactly_and_never_exceeds_it():
    command = np.array([2.0 * LIMIT, -3.0 * LIMIT, 1e3, np.nextafter(LIMIT, np.inf)])
    params = servo()
    held = hold_command(params, at_rest(), jnp.asarray(command)).command_rad
    np.testing.assert_array_equal(np.asarray(held), [LIMIT, -LIMIT, LIMIT, LIMIT])  # a clip is exact
    grid = tuple(np.linspace(0.0, T, 21))
    inside, state = fly(params, lambda k: command, 200, times=grid)  # 4 s, 52 τ
    # Bitwise: the output is the limit plus a product of exact sign, rounded monotonically.
    assert inside.max() <= LIMIT and inside.min() >= -LIMIT
    # 52 τ: the exponential has gone, but the chain stops n ulp short of the limit, n the largest with
    # n·(1 − exp(−T/τ)) < ½ (2 here): L − n·ulp·exp(−T/τ) rounds back to L − n·ulp, a fixed point of
    # rounding to nearest. 6e-17 rad, on the safe side.
    gap = LIMIT - np.abs(np.asarray(state.deflection_rad))
    ulps = int(0.5 / (1.0 - np.exp(-T / TAU)))
    np.testing.assert_array_equal(gap, ulps * np.spacing(LIMIT))
    # At the limit, a command beyond it holds the output there exactly, at every time.
    stop, _ = fly(params, lambda k: command, 5, start=[LIMIT, -LIMIT, LIMIT, LIMIT], times=grid)
    np.testing.assert_array_equal(stop, np.broadcast_to([LIMIT, -LIMIT, LIMIT, LIMIT], stop.shape))
    # From one stop to the other, never beyond either.
    swing, _ = fly(params, lambda k: -command, 50, start=state.deflection_rad, times=grid)
    assert swing.max() <= LIMIT and swing.min() >= -LIMIT


def test_sample_and_hold_uses_the_command_of_the_period_start():
    params = servo()
    first, second = np.array([0.1, 0.0, -0.1, 0.05]), np.array([-0.1, 0.1, 0.0, 0.0])

    def commanded(t):
        """The controller's wish at t [s], changing at 0.03 s, inside period 1 (0.02 to 0.04 s)."""
        return first if t < 0.03 else second

    # The servo samples at the period starts only: k·T, so period 1 holds `first` and period 2 `second`.
    inside, _ = fly(params, lambda k: commanded(k * T), 3)
    reference, _ = fly(params, lambda k: first if k < 2 else second, 3)
    np.testing.assert_array_equal(inside, reference)
    # Period 1 is the closed form toward `first`, from where period 0 left the fins.
    t = T + np.asarray(STAGES)
    np.testing.assert_allclose(inside[1], first * (1.0 - np.exp(-t / TAU))[:, None], rtol=0, atol=1e-15)


def test_rate_limit_clips_the_commanded_step_to_rate_times_tau_exactly():
    rate = 1.0  # rad/s: a step of at most rate·τ = 0.0769 rad
    start = np.array([0.0, 0.05, -0.05, 0.01])
    command = np.array([0.1, -0.1, 0.1, 0.015])  # the last within reach
    limited = hold_command(servo(rate=jnp.asarray(rate)), at_rest(start), jnp.asarray(command))
    expected = [start[0] + rate * TAU, start[1] - rate * TAU, start[2] + rate * TAU, command[3]]
    np.testing.assert_array_equal(np.asarray(limited.command_rad), expected)
    # The slew rate over the period (finite differences on a fine grid) never exceeds the limit.
    s = np.linspace(0.0, T, 2001)
    path = np.array([np.asarray(deflection_at(servo(rate=jnp.asarray(rate)), limited, x)) for x in s])
    assert np.abs(np.diff(path, axis=0) / np.diff(s)[:, None]).max() <= rate
    np.testing.assert_array_equal(np.asarray(limited.deflection_rad), start)
    free = hold_command(servo(), at_rest(start), jnp.asarray(command))
    np.testing.assert_array_equal(np.asarray(free.command_rad), command)
    # The deflection limit still applies first: a rate that allows any step leaves the clip alone.
    wide = hold_command(servo(rate=jnp.asarray(1e3)), at_rest(start), jnp.asarray(10.0 * command))
    np.testing.assert_array_equal(np.asarray(wide.command_rad), np.clip(10.0 * command, -LIMIT, LIMIT))


def test_offset_adds_exactly_and_stays_out_of_the_state():
    offset = np.array([1e-3, -2e-3, 0.0, 3e-3])
    command = lambda k: [0.1, -0.1, LIMIT, 2.0 * LIMIT]  # noqa: E731
    with_offset, end_with = fly(servo(offset=offset), command, 10)
    without, end_without = fly(servo(), command, 10)
    np.testing.assert_array_equal(with_offset, without + offset)
    np.testing.assert_array_equal(np.asarray(end_with.deflection_rad), np.asarray(end_without.deflection_rad))


def test_jit_and_vmap_lanes_equal_the_unbatched_servo():
    taus, rates = np.array([0.05, TAU, 0.12]), np.array([0.5, 2.0, 8.0])
    offsets = np.array([[1e-3, 0.0, 0.0, 0.0], [0.0, -1e-3, 0.0, 0.0], [0.0, 0.0, 2e-3, -1e-3]])
    commands = np.array([[0.1, -0.1, 0.3, 0.0], [0.05, 0.05, -0.2, 0.01], [-0.1, 0.0, 0.1, 0.17]])

    def run(params, command):
        def period(state, _):
            state = hold_command(params, state, command)
            samples = jnp.stack([deflection_at(params, state, s) for s in STAGES])
            return end_of_period(params, state, T), samples

        return jax.lax.scan(period, ServoState(jnp.zeros(4), jnp.zeros(4)), None, length=20)

    batch = ServoParams(jnp.asarray(taus), jnp.full(3, LIMIT), jnp.asarray(offsets), jnp.asarray(rates))
    end, samples = jax.jit(jax.vmap(run))(batch, jnp.asarray(commands))
    single = jax.jit(run)
    for i in range(3):
        lane = ServoParams(jnp.asarray(taus[i]), jnp.asarray(LIMIT), jnp.asarray(offsets[i]), jnp.asarray(rates[i]))
        end_i, samples_i = single(lane, jnp.asarray(commands[i]))
        np.testing.assert_array_equal(np.asarray(samples[i]), np.asarray(samples_i))
        np.testing.assert_array_equal(np.asarray(end.deflection_rad[i]), np.asarray(end_i.deflection_rad))
        np.testing.assert_array_equal(np.asarray(end.command_rad[i]), np.asarray(end_i.command_rad))

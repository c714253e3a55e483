"""Where a control step's time goes, kernel by kernel: XLA's own trace, read back with ``jax.profiler``.

    taskset -c 0 python benchmarks/kernel_profile.py [--campaign campaigns/lynx_nominal.toml]
        [--aero-model simplified] [--lanes 64] [--steps 500] [--top 25]

Flies ``--steps`` control periods of ``--lanes`` vmapped flights (started one block after the
rail, so they are burning and off it) on one XLA device, once untraced (µs per flight-step),
then once under the profiler with ``--xla_cpu_enable_xprof_traceme=true``, and prints the kernels
that took longest: calls, µs per call, and the size of the fused computation (operations, as XLA
compiled it). Tracing adds about 1 µs per kernel call; the untraced figure is the real one.
Pin it to one core (``taskset -c 0``) so that XLA's thread pool does not ping-pong the work.
"""

from __future__ import annotations

import os

os.environ["XLA_FLAGS"] = "--xla_force_host_platform_device_count=1 --xla_cpu_enable_xprof_traceme=true"

import argparse  # noqa: E402
import collections  # noqa: E402
import glob  # noqa: E402
import re  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402

import jax  # noqa: E402
import jax.numpy as jnp  # noqa: E402

from rocketmc.campaign import load_campaign, with_overrides  # noqa: E402
from rocketmc.campaign.runner import realization_params, sim_settings  # noqa: E402
from rocketmc.sim import events, flight  # noqa: E402


def computations(hlo_text: str) -> dict[str, str]:
    """Each computation's text in an HLO module, by name."""
    blocks = {}
    for block in re.split(r"\n(?=\S.*\{\n)", hlo_text):
        name = re.match(r"(?:ENTRY )?%?(\S+)", block)
        if name:
            blocks[name.group(1)] = block
    return blocks


def fusion_calls(hlo_text: str) -> list[tuple[str, str]]:
    """(kernel, the fused computation it calls) of each fusion in an HLO module."""
    return re.findall(r"%([\w.-]+) = .*? fusion\(.*?calls=%([\w.-]+)", hlo_text)


def fused_sizes(hlo_text: str) -> dict[str, int]:
    """Operations in the fused computation each fusion kernel calls, by kernel name."""
    sizes = {name: len(re.findall(r"= \S+ [\w-]+\(", block)) for name, block in computations(hlo_text).items()}
    return {kernel: sizes.get(callee, 0) for kernel, callee in fusion_calls(hlo_text)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--campaign", default="campaigns/lynx_nominal.toml")
    parser.add_argument("--aero-model", default="simplified")
    parser.add_argument("--lanes", type=int, default=64)
    parser.add_argument("--steps", type=int, default=500)
    parser.add_argument("--top", type=int, default=25)
    args = parser.parse_args()

    campaign = with_overrides(load_campaign(args.campaign), n_realizations=args.lanes, aero_model=args.aero_model)
    settings = sim_settings(campaign)
    master_key = jax.random.key(campaign.config.seed)

    @jax.jit
    @jax.vmap
    def start(index):
        p = realization_params(campaign, master_key, index)[0]
        return p, flight.fly_block(p, settings, flight.initial_state(p), jnp.uint32(0))

    params, state = start(jnp.arange(args.lanes, dtype=jnp.uint32))

    def steps(params, state):
        def one(p, s):
            noise = jax.tree_util.tree_map(lambda x: x[0], flight.block_noise(p, jnp.uint32(0), 1))
            step = lambda s, _: (flight.step(p, settings, events.rail_start_n(p), s, noise), None)  # noqa: E731
            return jax.lax.scan(step, s, None, args.steps)[0]

        return jax.vmap(one)(params, state)

    compiled = jax.jit(steps).lower(params, state).compile()
    jax.block_until_ready(compiled(params, state))
    best = min(_timed(compiled, params, state) for _ in range(3))
    print(f"{args.aero_model}, {args.lanes} lanes: {best / (args.lanes * args.steps) * 1e6:.3f} µs per flight-step")

    with tempfile.TemporaryDirectory() as trace_dir:
        jax.profiler.start_trace(trace_dir)
        jax.block_until_ready(compiled(params, state))
        jax.profiler.stop_trace()
        profile = jax.profiler.ProfileData.from_file(glob.glob(f"{trace_dir}/**/*.xplane.pb", recursive=True)[0])
    total, calls = collections.Counter(), collections.Counter()
    for plane in profile.planes:
        for line in plane.lines:
            if line.name.startswith("tf_XLAEigen"):  # XLA's worker threads: one event per kernel call
                for event in line.events:
                    total[event.name] += event.duration_ns
                    calls[event.name] += 1
    sizes = fused_sizes(compiled.as_text())
    print(f"{'kernel':<36} {'calls':>8} {'µs/call':>8} {'ops':>6}")
    for name, ns in total.most_common(args.top):
        if name in sizes:
            print(f"{name:<36} {calls[name]:>8} {ns / calls[name] / 1e3:>8.2f} {sizes[name]:>6}")


def _timed(compiled, *args) -> float:
    t0 = time.perf_counter()
    jax.block_until_ready(compiled(*args))
    return time.perf_counter() - t0


if __name__ == "__main__":
    main()

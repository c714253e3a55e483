"""Which source lines XLA's fused kernels compute, and how many times: duplicated arithmetic, found.

    python benchmarks/fusion_sources.py [--campaign campaigns/lynx_nominal_gnc_1s.toml] [--lanes N]
        [--by function|line] [--top 30]

Compiles one ``fly_block`` of ``--lanes`` vmapped flights (default ``runner.GROUP``, as campaigns fly; simplified
model) and reads its optimised HLO back (the period loop's body and what runs once a block, the flights' parameters
drawn from their keys): the number of kernels and of fused operations, then the source functions (or lines) of the
fused operations, each with its operation count and the number of kernels it appears in. XLA's CPU fusion copies an
elementwise producer into each consumer, so a function whose operations appear in tens of kernels is computed tens
of times a period (docs/performance.md, "The full GNC"). Operations are attributed to their innermost frame in
rocketmc's own code (``?``: none, e.g. JAX's internals).
"""

from __future__ import annotations

import os

os.environ.setdefault("XLA_FLAGS", "--xla_force_host_platform_device_count=1")

import argparse  # noqa: E402
import collections  # noqa: E402
import itertools  # noqa: E402
import re  # noqa: E402

import jax  # noqa: E402
import jax.numpy as jnp  # noqa: E402
from kernel_profile import computations, fused_sizes, fusion_calls  # noqa: E402

from rocketmc.campaign import load_campaign, with_overrides  # noqa: E402
from rocketmc.campaign.runner import GROUP, realization_params, sim_settings  # noqa: E402
from rocketmc.sim import flight  # noqa: E402


def _table(hlo: str, name: str) -> list[str]:
    """The rows of one of the HLO module's trailing tables (``FileNames``, ``StackFrames``, ...)."""
    lines = hlo[hlo.index(f"\n{name}\n") + len(name) + 2:].splitlines()
    return list(itertools.takewhile(lambda line: re.match(r"\d+ ", line), lines))


def source_frames(hlo: str) -> dict[int, list[tuple[str, str, int]]]:
    """Each stack frame id's call chain, innermost first: (file, function, line)."""
    files = {int(n): f.split('"')[1] for n, f in (line.split(" ", 1) for line in _table(hlo, "FileNames"))}
    functions = {int(n): f.split('"')[1] for n, f in (line.split(" ", 1) for line in _table(hlo, "FunctionNames"))}
    locations = {}
    for line in _table(hlo, "FileLocations"):
        n, file_id, function_id, at = map(int, re.match(r"(\d+) \{file_name_id=(\d+) function_name_id=(\d+) line=(\d+)",
                                                         line).groups())  # fmt: skip
        locations[n] = (files[file_id], functions[function_id], at)
    parents = {}
    for line in _table(hlo, "StackFrames"):
        n, location, parent = map(int, re.match(r"(\d+) \{file_location_id=(\d+) parent_frame_id=(\d+)", line).groups())
        parents[n] = (location, parent - 1)  # the parent is printed one up (measured: the chains read caller-ward)

    def chain(frame):
        out, seen = [], set()
        while frame in parents and frame not in seen:
            seen.add(frame)
            location, frame = parents[frame]
            out.append(locations[location])
        return out

    return {n: chain(n) for n in parents}


def attribution(hlo: str, by_line: bool) -> tuple[collections.Counter, dict[str, set]]:
    """(fused operations, kernels they appear in) by rocketmc source function (or line)."""
    frames, blocks = source_frames(hlo), computations(hlo)
    operations, kernels = collections.Counter(), collections.defaultdict(set)
    for kernel, callee in fusion_calls(hlo):
        for frame in re.findall(r"= \S+ [\w-]+\(.*stack_frame_id=(\d+)", blocks[callee]):
            ours = [f for f in frames.get(int(frame), []) if "/rocketmc/" in f[0]]
            source = "?" if not ours else f"{os.path.basename(ours[0][0])}:{ours[0][1]}" + (f":{ours[0][2]}" if by_line else "")
            operations[source] += 1
            kernels[source].add(kernel)
    return operations, kernels


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--campaign", default="campaigns/lynx_nominal_gnc_1s.toml")
    parser.add_argument("--lanes", type=int, default=GROUP)
    parser.add_argument("--by", choices=("function", "line"), default="function")
    parser.add_argument("--top", type=int, default=30)
    args = parser.parse_args()

    campaign = with_overrides(load_campaign(args.campaign), aero_model="simplified")
    settings, master_key = sim_settings(campaign), jax.random.key(campaign.config.seed)

    def params(index):
        return realization_params(campaign, master_key, index)[0]

    indices = jnp.arange(args.lanes, dtype=jnp.uint32)
    state = jax.eval_shape(jax.vmap(lambda i: flight.initial_state(params(i))), indices)
    block = jax.vmap(lambda i, s: flight.fly_block(params(i), settings, s, jnp.uint32(1)))
    hlo = jax.jit(block).lower(indices, state).compile().as_text()
    sizes = fused_sizes(hlo)
    print(f"{args.campaign}: {len(sizes)} kernels, {sum(sizes.values())} fused operations")
    operations, kernels = attribution(hlo, args.by == "line")
    print(f"{'operations':>10} {'kernels':>8}  source")
    for source, n in operations.most_common(args.top):
        print(f"{n:>10} {len(kernels[source]):>8}  {source}")


if __name__ == "__main__":
    main()

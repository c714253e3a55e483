"""The performance ratios (docs/performance.md), measured together in one run on one machine, never absolute times;
the sensors' cost is printed (``-s``), its bound of 1.3x not met yet (docs/performance.md).

Marked ``performance``: ``make test-performance`` runs them alone (CI, after ``make test``), since another test
process on the same cores would bias the timings; ``make test`` leaves them out, so that it passes on a busy
laptop. Each measurement (``rocketmc.bench.measure``) runs in
its own process, compiles its flight functions first, then times them in ``ROUNDS`` interleaved rounds
(best of each) in process CPU time, so that machine noise hits them alike and other programs on the
cores do not stretch them: the batch against single flights on every core (``ratios``, about 1.5 minutes
on the 2-core machine), the costs per flight on one core and one XLA thread (``costs``, about 3 minutes).
``-s`` prints the ratios.
"""

from __future__ import annotations

import pytest

from rocketmc.bench import measure

from .conftest import CAMPAIGNS

pytestmark = pytest.mark.performance

ROUNDS = 10
"""Interleaved rounds, the best of each function's kept. This VM's speed comes in phases seconds to minutes
long (a shared host): one 1024-flight batch's CPU time varies by up to 50 % from round to round, on two threads
as on one (measured: simplified 4.3-6.7 ms per flight, interpolated 5.8-9.1 ms, on one thread). The best
rounds agree within ~5 % on one thread; the ratio of bests was 1.34 there, 1.39-1.50 on two threads, where the
project's bound 1.5 failed CI once (1.502)."""
CAMPAIGN = CAMPAIGNS / "lynx_nominal.toml"


@pytest.fixture(scope="module")
def measured():
    r = measure("ratios", CAMPAIGN, repeats=ROUNDS)
    print(f"\nbatch of {r['batch']} against a loop of {r['loop_flights']}: {r['loop_over_batch']:.1f}x faster per flight")
    return r


@pytest.fixture(scope="module")
def cost():
    r = measure("costs", CAMPAIGN, repeats=ROUNDS)
    print(f"\none core: interpolated / simplified {r['interpolated_over_simplified']:.2f}x; closed loop "
          f"{1 / r['closed_over_open_loop']:.2f}x the open loop's flights/s; sensors "
          f"{r['sensors_over_closed_loop']:.2f}x the closed loop's cost; the full GNC "
          f"{r['full_gnc_speed_over_open_loop']:.2f}x the open loop's flights/s on one grid, "
          f"{r['full_gnc_speed_over_campaign_step']:.2f}x at the campaign's open-loop period")  # fmt: skip
    return r


def test_vmapped_batch_at_least_20x_faster_per_flight_than_a_loop(measured):
    # 20x is the project's bound, and the reason to vectorise: a batch spreads XLA's per-operation cost
    # over the SIMD lanes and flies on every core. A regression that serialises the batch (a lost
    # shard_map, a per-flight loop inside it, a host callback) brings it near the loop's cost.
    ratio = measured["loop_over_batch"]
    assert ratio >= 20.0, f"a vmapped batch is only {ratio:.1f}x faster per flight than single flights in a loop"


def test_interpolated_costs_at_most_1_5x_the_simplified(cost):
    # 1.5x is the project's bound on the tables' cost: the interpolated model must stay affordable for
    # whole campaigns (the thesis's cost 30x its simplified one, docs/lynx.md).
    ratio = cost["interpolated_over_simplified"]
    assert ratio <= 1.5, f"the interpolated aerodynamics cost {ratio:.2f}x the simplified per flight"


def test_closed_loop_flies_at_least_0_7x_the_open_loops_flights_per_second(cost):
    # 0.7x is the closed loop's bound: guidance, the gain lookup, u = −Kx and the servos' closed form at each RK4
    # stage, with perfect navigation, must not make the controller a luxury in a campaign. A per-step
    # host callback, a Python branch that recompiles, or small-matrix algebra under vmap would break it. Both fly
    # the controller's period: the open loop's longer periods (open_loop_dt_s) are a step choice, not a cost.
    flights_per_s = 1.0 / cost["closed_over_open_loop"]
    assert flights_per_s >= 0.7, f"the closed loop flies {flights_per_s:.2f}x the open loop's flights per second"


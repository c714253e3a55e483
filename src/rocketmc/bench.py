"""Benchmarks of a campaign on this machine (``rocketmc bench``, benchmarks/, tests/test_performance.py).

- throughput: flights per second after compilation, compile time [s] and peak memory [MB] for each
  aerodynamic model, precision and N;
- float32 against float64: their speeds, and the distances between the impact points of the same
  realizations flown in both;
- ratios timed together in one process: the vmapped batch against single flights in a loop (every
  core); in another, on one core and one thread, the costs per flight: the interpolated
  aerodynamics against the simplified, the closed loop (perfect navigation) against the
  same flights with the controller off, the closed loop on raw sensors against it, the full
  GNC (navigation filters) against the controller off (their bounds: docs/performance.md);
- the control periods per flight by phase (ascent, after apogee at the control period, the long descent ones).

Each measurement runs in a fresh Python process (``python -m rocketmc.bench SPEC``): its peak
resident memory (``ru_maxrss``, compilation included) is its own, and ``ROCKETMC_PRECISION`` (read
when rocketmc is imported) can choose float32.
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import platform
import resource
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from importlib import metadata, resources
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np

from .runtime import PRECISION
from .ellipse import chi2_scale, confidence_ellipse
from .campaign import load_campaign, run_chunks, with_overrides
from .campaign.derivatives import batch_function, ellipse_area_m2
from .campaign.runner import GROUP, batch_size, chunking, compile_chunk, realization, realization_params, sim_settings
from .sim.flight import fly, regular_period_s
from .sim.state import Status, done

DEFAULT_CAMPAIGN = Path(str(resources.files("rocketmc") / "data" / "campaigns" / "lynx_nominal.toml"))
MODELS = ("simplified", "interpolated")
PRECISIONS = ("float64", "float32")
LOOP_FLIGHTS = 8
"""Single flights per timed loop (lynx_nominal: ~0.05–0.1 s each on the 2-core machine)."""
QUEUE_PER_LANE = 4
"""Flights per lane in the timed batch: 1024 on 2 cores (512 on the costs' one), about the default chunk (1000)."""


# --- measurements (in the measuring process) -----------------------------------------------------


def single_flights(campaign) -> Callable:
    """``f(master_key, indices)``: the realizations flown one at a time, a compiled single flight
    (``jit`` of ``runner.realization``, one device) called in a Python loop."""
    settings = sim_settings(campaign)
    key = jax.random.key(campaign.config.seed)
    one = jax.jit(lambda k, i: realization(campaign, settings, k, i)).lower(key, np.uint32(0)).compile()
    return lambda master_key, indices: [jax.block_until_ready(one(master_key, i)) for i in indices]


def seconds_per_flight(functions: dict[str, tuple[Callable, int]], master_key, repeats: int) -> dict[str, float]:
    """Best process CPU time per flight [s] of each ``name: (f, n)``, ``f(master_key, indices 0..n-1)``,
    over ``repeats`` rounds that interleave the functions (so that machine noise hits all alike).

    CPU time, not wall time: other programs on the cores (a busy laptop, a shared CI runner) stretch
    wall times, unevenly between functions, but not this process's CPU time. XLA's CPU thread pool
    keeps every core busy even for a single flight (measured on 2 cores: a loop's CPU time is twice its
    wall time, as a batch's is), so the ratios are those of wall times on an idle machine."""
    best = dict.fromkeys(functions, float("inf"))
    for _ in range(repeats):
        for name, (f, n) in functions.items():
            indices = np.arange(n, dtype=np.uint32)
            t0 = time.process_time()
            jax.block_until_ready(f(master_key, indices))
            best[name] = min(best[name], (time.process_time() - t0) / n)
    return best


def _timed_together(campaign, builders: dict[str, tuple[Callable, tuple, int]], repeats: int) -> dict[str, float]:
    """``seconds_per_flight`` of each ``name: (build, args, n)``'s function ``build(*args)``, the functions
    compiled concurrently (XLA compiles outside the GIL), then timed together."""
    with ThreadPoolExecutor() as pool:
        compiling = {name: (pool.submit(build, *args), n) for name, (build, args, n) in builders.items()}
        functions = {name: (f.result(), n) for name, (f, n) in compiling.items()}
    return seconds_per_flight(functions, jax.random.key(campaign.config.seed), repeats)


def _batch() -> int:
    """The timed batch: ``QUEUE_PER_LANE`` flights per lane, as a chunk flies them."""
    return batch_size(QUEUE_PER_LANE * GROUP * jax.local_device_count())


def ratios(campaign, repeats: int = 3) -> dict:
    """The batch-against-loop ratio on ``campaign``, simplified model, on every core: seconds per flight [s] of
    ``LOOP_FLIGHTS`` single flights in a loop and of a vmapped batch (``_batch``), timed together
    (``_timed_together``); ``loop_over_batch``."""
    simplified = with_overrides(campaign, aero_model="simplified")
    batch = _batch()
    s = _timed_together(campaign, {
        "loop": (single_flights, (simplified,), LOOP_FLIGHTS),
        "batch": (compile_chunk, (simplified, batch), batch),
    }, repeats)  # fmt: skip
    return {"loop_flights": LOOP_FLIGHTS, "batch": batch, "s_per_flight": s, "loop_over_batch": s["loop"] / s["batch"]}


BENCH_AIRBRAKES = {"target_apogee_m": 1000.0, "panels": {"count": 3, "width_m": 0.05, "max_extension_m": 0.02}}
"""The air brakes ``costs`` adds to a campaign without its own (truth navigation; their cost per period does not
depend on their numbers: the prediction runs at every GNC tick)."""


def costs(campaign, repeats: int = 3) -> dict:
    """The cost ratios of docs/performance.md on ``campaign``, per flight of vmapped batches (``_batch``), timed
    together: the interpolated aerodynamics against the simplified (controller off), the closed loop (the
    campaign's [gnc] or its defaults, perfect navigation) against the same flights with the controller off
    (simplified), the closed loop on raw sensors (the campaign's [avionics] or the thesis's parts)
    against the closed loop on perfect navigation, and the flights/s of the controller off against the full GNC
    (the closed loop on the navigation filters). The ratios compare flights on one grid: the open loop flies the
    controller's period (``open_loop_dt_s`` unset), so that they measure what the controller, the sensors and the
    filters cost a period; "campaign_step" is the open loop at the campaign's own ``open_loop_dt_s`` (longer
    periods where the campaign sets them) and ``full_gnc_speed_over_campaign_step`` the full GNC against it.
    "airbrakes": the open loop with the campaign's [airbrakes] (``BENCH_AIRBRAKES`` if it has none) on the true state,
    which flies every period on the GNC grid, against the open loop without them (``airbrakes_over_open_loop``).
    Run on one core with one XLA thread (``measure(..., kind="costs")``): a cost is the
    work a flight takes, and on one thread the best rounds of a function agree within ~5 % where the
    two-core rounds, whose threads wait on each other, spread ~10 % (measured on the 2-core VM)."""
    own_brakes = campaign.config.airbrakes is not None
    bare = with_overrides(campaign, aero_model="simplified", controller=False, sensors=False)
    campaign_step = with_overrides(bare, airbrakes=False) if own_brakes else bare
    open_loop = with_overrides(campaign_step, values={"simulation.open_loop_dt_s": None})
    braked = with_overrides(bare, values={"simulation.open_loop_dt_s": None,
                                          **({} if own_brakes else {"airbrakes": BENCH_AIRBRAKES})})  # fmt: skip
    closed_loop = with_overrides(open_loop, controller=True)
    batch = _batch()
    s = _timed_together(campaign, {
        "campaign_step": (compile_chunk, (campaign_step, batch), batch),
        "simplified": (compile_chunk, (open_loop, batch), batch),
        "interpolated": (compile_chunk, (with_overrides(open_loop, aero_model="interpolated"), batch), batch),
        "closed_loop": (compile_chunk, (closed_loop, batch), batch),
        "sensors": (compile_chunk, (with_overrides(closed_loop, sensors=True), batch), batch),
        "filters": (compile_chunk, (with_overrides(closed_loop, navigation="filters"), batch), batch),
        "airbrakes": (compile_chunk, (braked, batch), batch),
    }, repeats)  # fmt: skip
    return {"batch": batch, "s_per_flight": s, "interpolated_over_simplified": s["interpolated"] / s["simplified"],
            "closed_over_open_loop": s["closed_loop"] / s["simplified"],
            "sensors_over_closed_loop": s["sensors"] / s["closed_loop"],
            "full_gnc_speed_over_open_loop": s["simplified"] / s["filters"],
            "full_gnc_speed_over_campaign_step": s["campaign_step"] / s["filters"],
            "airbrakes_over_open_loop": s["airbrakes"] / s["simplified"]}  # fmt: skip


GRADIENT_FLIGHTS = 1000
"""Flights of the gradient's batch (``gradient_cost``)."""
GRADIENT_PARAMS = ("rocket.dry_mass_kg", "rocket.aero.drag_scale", "launch.elevation_deg")
"""The design numbers the bench's gradient is taken with respect to."""


def gradient_cost(campaign, mode: str, repeats: int = 2) -> dict:
    """The 95 % ellipse's area over ``GRADIENT_FLIGHTS`` flights of ``campaign`` (``derivatives.ellipse_area_m2``),
    its forward pass (``mode`` "forward": the flights vmapped, ``simulate_one``) or its value and reverse-mode
    gradient with respect to ``GRADIENT_PARAMS`` ("reverse": ``simulate_bounded``), compiled, then timed (best of ``repeats``, wall time [s]); the process's peak memory is the
    caller's (``_measure``)."""
    settings, master = sim_settings(campaign), jax.random.key(campaign.config.seed)
    indices = jnp.arange(GRADIENT_FLIGHTS, dtype=jnp.uint32)
    level_scale, shift = chi2_scale(0.95), jnp.zeros(len(GRADIENT_PARAMS))
    t0 = time.perf_counter()
    x0, flights = batch_function(campaign, settings, master, indices, GRADIENT_PARAMS, reverse=mode != "forward")

    def area(s):  # of a design change s
        outputs, (_, status) = flights(x0 + s[None, :])
        return ellipse_area_m2(outputs, status, level_scale)

    run = jax.jit(area if mode == "forward" else jax.value_and_grad(area)).lower(shift).compile()
    compile_s, seconds = time.perf_counter() - t0, []
    for _ in range(repeats):
        t0 = time.perf_counter()
        jax.block_until_ready(run(shift))
        seconds.append(time.perf_counter() - t0)
    return {"mode": mode, "flights": GRADIENT_FLIGHTS, "params": list(GRADIENT_PARAMS), "compile_s": compile_s,
            "run_s": min(seconds)}  # fmt: skip


PHASE_FLIGHTS = 32
"""Realizations whose control periods ``periods_by_phase`` counts."""


def periods_by_phase(campaign, repeats: int | None = None) -> dict:
    """Control periods per flight, median over ``PHASE_FLIGHTS`` realizations (``repeats`` unused: nothing is timed):
    in all, in the ascent (to apogee), after apogee in regular periods (``sim.flight.regular_period_s``: the canopies'
    openings and settling, wind-layer boundaries) and in the longer steady-descent periods, each with its median
    seconds of flight."""
    settings = sim_settings(campaign)
    master = jax.random.key(campaign.config.seed)
    regular_s = regular_period_s(realization_params(campaign, master, jnp.uint32(0))[0], settings)
    n_periods = math.ceil(settings.max_time_s / regular_s)

    def periods(index):
        p, _ = realization_params(campaign, master, index)
        record = lambda s: (s.t, jnp.isfinite(s.events.apogee_time), done(s))  # noqa: E731
        return fly(p, settings, n_periods, record=record)[1]

    indices = jnp.arange(PHASE_FLIGHTS, dtype=jnp.uint32)
    t, past_apogee, landed = map(np.asarray, jax.jit(jax.vmap(periods))(indices))
    length = np.diff(t, axis=1, prepend=0.0)
    flying = ~np.concatenate([np.zeros((PHASE_FLIGHTS, 1), bool), landed[:, :-1]], axis=1)  # the landing one counts
    regular = length <= regular_s * (1 + 1e-9)  # the sum of periods rounds: not a long one
    phases = {"ascent": flying & ~past_apogee, "after_apogee_regular": flying & past_apogee & regular,
              "after_apogee_long": flying & past_apogee & ~regular}  # fmt: skip
    return {"flights": PHASE_FLIGHTS, "regular_period_s": regular_s, "periods": float(np.median(flying.sum(1))),
            **{name: {"periods": float(np.median(mask.sum(1))),
                      "seconds": float(np.median(np.where(mask, length, 0.0).sum(1)))}
               for name, mask in phases.items()}}  # fmt: skip


@contextlib.contextmanager
def float32_draws():
    """Make ``jax.random``'s normal, uniform and categorical draw in float32 (then cast to the
    requested dtype) while a campaign is compiled. A float64 draw takes 64 random bits and a float32
    one 32, so the two precisions otherwise fly different realizations from the same seed; with this,
    float64 flies exactly the dispersions and gusts that float32 draws."""
    normal, uniform, categorical = jax.random.normal, jax.random.uniform, jax.random.categorical
    jax.random.normal = lambda key, shape=(), dtype=float: normal(key, shape, jnp.float32).astype(dtype)
    jax.random.uniform = lambda key, shape=(), dtype=float, minval=0.0, maxval=1.0: uniform(
        key, shape, jnp.float32, minval, maxval
    ).astype(dtype)
    jax.random.categorical = lambda key, logits, *args, **kwargs: categorical(
        key, jnp.asarray(logits, jnp.float32), *args, **kwargs
    )
    try:
        yield
    finally:
        jax.random.normal, jax.random.uniform, jax.random.categorical = normal, uniform, categorical


def throughput(campaign, chunk_size: int | None = None, impacts: str | None = None) -> dict:
    """Fly ``campaign`` with ``run_chunks``: chunk size, compile time [s], wall time of the chunks
    after it [s], flights/s, ok flights and the count of each failure status; ``impacts``: also save
    the impact points, status and drawn inputs in this ``.npz`` file."""
    t0 = time.perf_counter()
    runs = run_chunks(campaign, chunk_size)
    compile_s = next(runs)
    keys = ("impact_north_m", "impact_east_m", "status") if impacts else ("status",)
    kept = [{k: c.outputs[k] for k in keys} | (c.inputs if impacts else {}) for c in runs]
    run_s = time.perf_counter() - t0 - compile_s
    flown = {k: np.concatenate([c[k] for c in kept]) for k in kept[0]}
    if impacts:
        np.savez(impacts, **flown)
    codes, counts = np.unique(flown["status"], return_counts=True)
    return {"chunk_size": chunking(campaign, chunk_size)[0], "compile_s": compile_s, "run_s": run_s,
            "flights_per_s": campaign.config.n_realizations / run_s, "ok": int(counts[codes == 0].sum()),
            "failed": {Status(c).name: int(k) for c, k in zip(codes, counts) if c != 0}}  # fmt: skip


def _measure(spec: dict) -> dict:
    """One measurement in this process (``spec`` from ``_subprocess``), with this process's
    precision and peak resident memory [MB]."""
    campaign = load_campaign(spec["campaign"])
    if spec["kind"] in WHOLE_CAMPAIGN_KINDS:
        result = WHOLE_CAMPAIGN_KINDS[spec["kind"]](campaign, spec["repeats"])
    else:
        campaign = with_overrides(campaign, n_realizations=spec["n"], aero_model=spec["model"])
        with float32_draws() if spec["float32_draws"] else contextlib.nullcontext():
            result = throughput(campaign, spec["chunk_size"], spec["impacts"])
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss  # kB on Linux, bytes on macOS
    return {**result, "precision": PRECISION, "peak_rss_mb": rss / (2**20 if sys.platform == "darwin" else 2**10)}


# --- orchestration (in the calling process) ------------------------------------------------------

WHOLE_CAMPAIGN_KINDS = {"ratios": ratios, "costs": costs, "periods": periods_by_phase,
                        "forward_pass": lambda c, repeats: gradient_cost(c, "forward", repeats),
                        "gradient": lambda c, repeats: gradient_cost(c, "reverse", repeats)}
"""The measurements of the campaign file as it is (no N, model or chunk size of their own), by kind: the ratios and
costs time several flight functions together; the periods by phase count."""


class BenchError(RuntimeError):
    """A measuring process failed; the message is one line."""


ONE_THREAD_XLA_FLAGS = (
    "--xla_force_host_platform_device_count=1 --xla_cpu_multi_thread_eigen=false intra_op_parallelism_threads=1"
)
"""XLA on one device and one thread: the cost measurements' process (``costs``, pinned to one core)."""


@contextlib.contextmanager
def _one_core():
    """This thread pinned to one of its cores while inside (where the OS can pin): a process it starts inherits
    that affinity, every thread of it included."""
    if not hasattr(os, "sched_setaffinity"):
        yield
        return
    cores = os.sched_getaffinity(0)
    os.sched_setaffinity(0, {min(cores)})
    try:
        yield
    finally:
        os.sched_setaffinity(0, cores)


def _subprocess(precision: str, cache: str | None = None, **spec) -> dict:
    """``_measure(spec)`` in a fresh process with ``ROCKETMC_PRECISION=precision``; ``costs`` on one core
    with ``ONE_THREAD_XLA_FLAGS``; ``cache``: its folder of compiled programs (``runtime.CACHE_DIR``, XLA's
    executables in it too), by default the user's."""
    env = {**os.environ, "ROCKETMC_PRECISION": precision}
    if cache is not None:
        env["ROCKETMC_CACHE_DIR"] = cache
        env.pop("JAX_COMPILATION_CACHE_DIR", None)
    one_core = spec["kind"] == "costs"
    if one_core:
        env["XLA_FLAGS"] = ONE_THREAD_XLA_FLAGS
    command = [sys.executable, "-m", "rocketmc.bench", json.dumps(spec)]
    with _one_core() if one_core else contextlib.nullcontext():
        done = subprocess.run(command, env=env, capture_output=True, text=True)
    if done.returncode != 0:
        last = (done.stderr.strip().splitlines() or [f"exit status {done.returncode}"])[-1]
        what = spec["kind"] if spec["kind"] in WHOLE_CAMPAIGN_KINDS else f"{spec['model']}, N = {spec['n']}"
        raise BenchError(f"the measurement ({what}, {precision}) failed: {last}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def _impact_difference(float64_npz: str, float32_npz: str) -> dict:
    """Distances [m] between the impact points of the same realizations flown in both precisions
    (ok in both), the largest relative difference of their drawn inputs (float32 rounding: ~1e-7),
    and the two 95 % ellipses' areas [m²]."""
    a, b = np.load(float64_npz), np.load(float32_npz)
    ok = (a["status"] == 0) & (b["status"] == 0)
    d = np.hypot(a["impact_north_m"][ok] - b["impact_north_m"][ok], a["impact_east_m"][ok] - b["impact_east_m"][ok])
    inputs = [k for k in a.files if k not in ("impact_north_m", "impact_east_m", "status")]
    area = {p: confidence_ellipse(x["impact_north_m"][ok], x["impact_east_m"][ok]).area_m2
            for p, x in (("float64", a), ("float32", b))}  # fmt: skip
    return {
        "compared": int(ok.sum()),
        "status_differs": int((a["status"] != b["status"]).sum()),
        "inputs_max_relative_difference": max(
            float(np.max(np.abs(a[k] - b[k]) / np.maximum(np.abs(a[k]), np.finfo(float).tiny))) for k in inputs
        ),
        "impact_difference_m": {"median": float(np.median(d)), "p95": float(np.percentile(d, 95)),
                                "max": float(d.max())},
        "ellipse95_area_m2": {**area, "relative_difference": area["float32"] / area["float64"] - 1.0},
    }  # fmt: skip


def machine() -> dict:
    """CPU, core count, XLA devices and versions of this machine."""
    cpuinfo = Path("/proc/cpuinfo")
    lines = cpuinfo.read_text().splitlines() if cpuinfo.exists() else []
    names = [line.split(":", 1)[1].strip() for line in lines if line.startswith("model name")]
    return {
        "cpu": names[0] if names else platform.processor(),
        "cores": len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count(),
        "devices": jax.local_device_count(),
        "platform": jax.default_backend(),
        "python": platform.python_version(),
        "jax": jax.__version__,
        "jaxlib": metadata.version("jaxlib"),
    }


def run_benchmarks(
    campaign: str | Path = DEFAULT_CAMPAIGN,
    sizes: tuple[int, ...] = (1000,),
    models: tuple[str, ...] = MODELS,
    precisions: tuple[str, ...] = PRECISIONS,
    chunk_size: int | None = None,
    log: Callable[[str], None] = lambda line: None,
) -> dict:
    """Every (N, model, precision) throughput measurement, then the ratios (in the first precision),
    each in its own process; ``log`` receives one line per measurement. With both precisions, the
    float64 run of the smallest N and first model flies float32's draws (``float32_draws``), and the
    report compares their impact points. Raises ConfigError for a bad campaign or model."""
    path = str(Path(campaign).resolve())
    base = load_campaign(path)
    for model in dict.fromkeys((*models, *MODELS)):  # the ratios fly both MODELS
        with_overrides(base, aero_model=model)  # a model the campaign cannot fly fails here
    report = {"campaign": base.config.name, "campaign_file": path, "machine": machine(), "measurements": []}
    compared = (min(sizes), models[0]) if set(PRECISIONS) <= set(precisions) else None
    with tempfile.TemporaryDirectory() as tmp:
        impacts = {p: str(Path(tmp) / f"{p}.npz") for p in PRECISIONS}
        cache = str(Path(tmp) / "cache")  # empty: each (model, precision)'s first process compiles cold
        for n in sizes:
            for model in models:
                for precision in precisions:
                    same = (n, model) == compared
                    r = {"model": model, "n": n, "float32_draws": same and precision == "float64"}
                    r |= _subprocess(precision, cache, kind="throughput", campaign=path, chunk_size=chunk_size,
                                     impacts=impacts[precision] if same else None, **r)  # fmt: skip
                    report["measurements"].append(r)
                    log(f"{model} {precision} N = {n}: compile {r['compile_s']:.1f} s, {r['flights_per_s']:.0f} "
                        f"flights/s, {r['ok']} ok, peak RSS {r['peak_rss_mb']:.0f} MB")  # fmt: skip
        first = report["measurements"][0]
        warm = _subprocess(precisions[0], cache, kind="throughput", campaign=path, chunk_size=chunk_size,
                           impacts=None, model=models[0], n=sizes[0], float32_draws=first["float32_draws"])  # fmt: skip
        report["compile_s"] = {"model": models[0], "precision": precisions[0], "n": sizes[0],
                               "cold": first["compile_s"], "warm": warm["compile_s"]}  # fmt: skip
        log(f"compile ({models[0]}, {precisions[0]}): {first['compile_s']:.1f} s cold, {warm['compile_s']:.1f} s warm "
            "(a fresh process, the program from the disk cache)")  # fmt: skip
        if compared:
            c = _impact_difference(impacts["float64"], impacts["float32"])
            report["float32_vs_float64"] = {"n": compared[0], "model": compared[1], **c}
            log(f"float32 against float64 on the same realizations: impact points "
                f"{c['impact_difference_m']['median']:.2f} m apart (median)")  # fmt: skip
    r = report["ratios"] = measure("ratios", path, precisions[0])
    log(f"batch ({precisions[0]}): {r['loop_over_batch']:.1f}x faster per flight than a loop")
    r = report["periods_by_phase"] = measure("periods", path, precisions[0])
    log(f"periods per flight ({precisions[0]}, median of {r['flights']}): {r['periods']:.0f}, "
        f"{r['ascent']['periods']:.0f} up to apogee")  # fmt: skip
    c = report["costs"] = measure("costs", path, precisions[0])
    log(f"costs ({precisions[0]}, one core): interpolated {c['interpolated_over_simplified']:.2f}x the simplified, "
        f"closed loop {1 / c['closed_over_open_loop']:.2f}x the open loop's flights/s, sensors "
        f"{c['sensors_over_closed_loop']:.2f}x the closed loop's cost, the full GNC (filters) "
        f"{c['full_gnc_speed_over_open_loop']:.2f}x the open loop's flights/s on one grid, "
        f"{c['full_gnc_speed_over_campaign_step']:.2f}x at the campaign's open-loop period, air brakes "
        f"{c['airbrakes_over_open_loop']:.2f}x the open loop's cost")  # fmt: skip
    forward, gradient = (measure(kind, path, precisions[0], repeats=2) for kind in ("forward_pass", "gradient"))
    report["gradient"] = {"forward": forward, "reverse": gradient}
    log(f"gradient of the ellipse's area over {gradient['flights']} flights ({precisions[0]}): "
        f"{gradient['run_s'] / forward['run_s']:.1f}x the forward pass's time, "
        f"{gradient['peak_rss_mb'] / forward['peak_rss_mb']:.1f}x its peak memory")  # fmt: skip
    return report


def measure(kind: str, campaign: str | Path = DEFAULT_CAMPAIGN, precision: str = "float64", repeats: int = 3) -> dict:
    """``ratios`` or ``costs`` (``kind``) of the campaign file in their own process, best of ``repeats``
    interleaved rounds each."""
    return _subprocess(precision, kind=kind, campaign=str(Path(campaign).resolve()), repeats=repeats)


def format_report(report: dict) -> str:
    """The report as a readable table and a few sentences."""
    m = report["machine"]
    lines = [
        f"{report['campaign']}: {m['cpu']}, {m['cores']} cores ({m['devices']} XLA {m['platform']} devices), "
        f"jax {m['jax']}, Python {m['python']}",
        f"  {'model':<13}{'precision':<10}{'N':>8}{'chunk':>7}{'compile s':>11}{'run s':>9}{'flights/s':>11}"
        f"{'ok':>8}{'peak RSS MB':>13}  failed",
    ]  # fmt: skip
    rows = report["measurements"]
    for r in rows:
        failed = ", ".join(f"{name} {k}" for name, k in r["failed"].items()) or "-"
        lines.append(f"  {r['model']:<13}{r['precision']:<10}{r['n']:>8}{r['chunk_size']:>7}{r['compile_s']:>11.1f}"
                     f"{r['run_s']:>9.1f}{r['flights_per_s']:>11.1f}{r['ok']:>8}{r['peak_rss_mb']:>13.0f}"
                     f"  {failed}")  # fmt: skip
    c = report["compile_s"]
    lines.append(f"  compile ({c['model']}, {c['precision']}, N = {c['n']}): {c['cold']:.1f} s cold (empty cache), "
                 f"{c['warm']:.1f} s warm (a fresh process, the program from the disk cache); later rows of a model "
                 "and precision are warm")  # fmt: skip
    rate = {(r["model"], r["precision"], r["n"]): r["flights_per_s"] for r in rows}
    lines += [f"  interpolated / simplified cost per flight ({p}, N = {n}, separate runs): "
              f"{rate['simplified', p, n] / fps:.2f}x"
              for (model, p, n), fps in rate.items()
              if model == "interpolated" and ("simplified", p, n) in rate]  # fmt: skip
    lines += [f"  float32 / float64 speed ({model}, N = {n}): {fps / rate[model, 'float64', n]:.2f}x"
              for (model, p, n), fps in rate.items() if p == "float32" and (model, "float64", n) in rate]  # fmt: skip
    if "float32_vs_float64" in report:
        c = report["float32_vs_float64"]
        d, a = c["impact_difference_m"], c["ellipse95_area_m2"]
        lines.append(
            f"  float32 against float64 on the same realizations ({c['model']}, N = {c['n']}, {c['compared']} ok in "
            f"both, {c['status_differs']} with another status): impact points {d['median']:.2f} m apart (median), "
            f"{d['p95']:.2f} m (95th percentile), {d['max']:.2f} m (max); 95 % ellipse area {a['float32'] / 1e6:.4f} "
            f"km² against {a['float64'] / 1e6:.4f} km² ({100 * a['relative_difference']:+.3f} %)"
        )
    r = report["ratios"]
    s = r["s_per_flight"]
    lines.append(
        f"  timed together ({r['precision']}): a vmapped batch of {r['batch']} flies {r['loop_over_batch']:.1f}x "
        f"faster per flight than {r['loop_flights']} single flights in a loop ({1e3 * s['batch']:.2f} against "
        f"{1e3 * s['loop']:.1f} ms, simplified)"
    )
    r = report["periods_by_phase"]
    ascent, regular, long = (r[name] for name in ("ascent", "after_apogee_regular", "after_apogee_long"))
    lines.append(f"  control periods per flight (median of {r['flights']}): {r['periods']:.0f}; to apogee "
                 f"{ascent['periods']:.0f} ({ascent['seconds']:.1f} s of flight); after it {regular['periods']:.0f} of "
                 f"{r['regular_period_s']:g} s or less ({regular['seconds']:.1f} s) and {long['periods']:.0f} longer ones "
                 f"in steady descent ({long['seconds']:.1f} s)")  # fmt: skip
    c = report["costs"]
    s = c["s_per_flight"]
    lines.append(
        f"  costs per flight on one core, timed together (batches of {c['batch']}): interpolated / simplified "
        f"{c['interpolated_over_simplified']:.2f}x ({1e3 * s['interpolated']:.2f} against {1e3 * s['simplified']:.2f} "
        f"ms); closed loop (perfect navigation, simplified) {1 / c['closed_over_open_loop']:.2f}x the flights/s "
        f"of the same flights with the controller off, on the controller's period ({1e3 * s['closed_loop']:.2f} ms); "
        f"on raw sensors {c['sensors_over_closed_loop']:.2f}x the closed loop's cost ({1e3 * s['sensors']:.2f} ms); "
        f"the full GNC (thesis sensors, MEKF and Kalman filter) {c['full_gnc_speed_over_open_loop']:.2f}x the "
        f"flights/s of the controller off ({1e3 * s['filters']:.2f} ms), "
        f"{c['full_gnc_speed_over_campaign_step']:.2f}x those flown at the campaign's open-loop period "
        f"({1e3 * s['campaign_step']:.2f} ms); air brakes flown to a target on the true state "
        f"{c['airbrakes_over_open_loop']:.2f}x the open loop's cost ({1e3 * s['airbrakes']:.2f} ms)"
    )
    forward, gradient = report["gradient"]["forward"], report["gradient"]["reverse"]
    lines.append(
        f"  the 95 % ellipse's area over {gradient['flights']} flights and its reverse-mode gradient with respect to "
        f"{len(gradient['params'])} design numbers: {gradient['run_s']:.1f} s "
        f"against {forward['run_s']:.1f} s for the forward pass ({gradient['run_s'] / forward['run_s']:.1f}x), "
        f"peak memory {gradient['peak_rss_mb']:.0f} against {forward['peak_rss_mb']:.0f} MB; compiled in "
        f"{gradient['compile_s']:.0f} and {forward['compile_s']:.0f} s"
    )
    return "\n".join(lines)


if __name__ == "__main__":  # one measurement: python -m rocketmc.bench SPEC (JSON); its result on stdout
    print(json.dumps(_measure(json.loads(sys.argv[1]))))

"""The closed loop's guidance or the air brakes' gains tuned by gradient descent through a Monte Carlo
(``rocketmc tune``).

The objective is a statistic of a batch of training flights (``OBJECTIVES``): the 95 % landing ellipse's area, or
the apogee's RMS error to a target. Each step flies the batch once forward and once backward (reverse mode through
``sim.flight.simulate_bounded``: ``derivatives.batch_function``) for the objective's gradient with respect to the
numbers tuned (``model.GUIDANCE_NUMBERS``, ``model.AIRBRAKE_NUMBERS``), shared by every flight, and takes an Adam
step (optax) on the numbers scaled by their starting values, projected back into the ranges the campaign schema
allows. The training flights are drawn from another master seed than the campaign's (``TRAINING_SEED_OFFSET``), so
that the campaign's own realizations, with which ``rocketmc run`` and ``compare`` pair it, stay held out; by default
they fly without the campaign's turbulence (``calm``), whose gusts make a flight only piecewise continuous in the
numbers.
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import time
import typing
from collections.abc import Callable, Sequence
from pathlib import Path

import annotated_types
import jax
import jax.numpy as jnp
import numpy as np
import optax

from ..ellipse import chi2_scale
from .derivatives import DIFFERENTIATED_OUTPUTS, batch_function, check_inputs, ellipse_area_m2
from .errors import ConfigError
from .model import GUIDANCE_NUMBERS, airbrake_numbers
from .record import Campaign
from .runner import sim_settings
from .schema import AirbrakeReferenceConfig, AirbrakesControlConfig, CampaignConfig, GuidanceConfig

SECTIONS = {"gnc.guidance": GuidanceConfig, "airbrakes.reference": AirbrakeReferenceConfig,
            "airbrakes": AirbrakesControlConfig}  # fmt: skip
"""The sections whose numbers can be tuned, by path prefix (a section before those it is inside), and their schema."""

OBJECTIVES = {"ellipse_area": "the 95 % landing ellipse's area [m²]", "apogee_error": "the apogee's RMS error to the target [m]"}
TRAINING_SEED_OFFSET = 1
"""The training flights are the realizations of master seed (the campaign's + this): the campaign's own are held out."""
LEVEL = 0.95
_APOGEE = DIFFERENTIATED_OUTPUTS.index("apogee_agl_m")


def objective_value(objective: str, outputs, status, apogee_target_m: float | None = None):
    """``objective`` of a batch's ``DIFFERENTIATED_OUTPUTS`` (flights, 4) over its ok flights (status 0):
    "ellipse_area" [m²] (``derivatives.ellipse_area_m2``) or "apogee_error", √mean (apogee − target)² [m]."""
    if objective == "ellipse_area":
        return ellipse_area_m2(outputs, status, chi2_scale(LEVEL))
    ok = (status == 0) & jnp.isfinite(outputs[:, _APOGEE])
    error = jnp.where(ok, outputs[:, _APOGEE] - apogee_target_m, 0.0)
    return jnp.sqrt((error**2).sum() / jnp.maximum(ok.sum(), 1).astype(error.dtype))


def _section(path: str) -> tuple[str, str, str]:
    """(section, field, index) of a tunable number's path (``SECTIONS``): "gnc.guidance.integrator_gain.0" ->
    ("gnc.guidance", "integrator_gain", "0")."""
    section = next(prefix for prefix in SECTIONS if path.startswith(prefix + "."))
    name, _, index = path.removeprefix(section + ".").partition(".")
    return section, name, index


def bounds(path: str) -> tuple[float, float]:
    """The range [low, high] the campaign schema allows a tunable number (``GUIDANCE_NUMBERS``' or
    ``AIRBRAKE_NUMBERS``' path) in; a strict bound moved inside by 10⁻⁹ of its size."""
    section, name, _ = _section(path)
    field = SECTIONS[section].model_fields[name]
    constraints, pending = list(field.metadata), list(typing.get_args(field.annotation))
    while pending:  # the bounds of an Annotated type inside the field's annotation (Height | None, list[...])
        arg = pending.pop()
        pending += typing.get_args(arg)
        for meta in getattr(arg, "__metadata__", ()):
            constraints += getattr(meta, "metadata", [meta])
    low, high = -math.inf, math.inf
    nudge = lambda x, sign: x + sign * 1e-9 * max(1.0, abs(x))  # noqa: E731
    for c in constraints:
        low = c.ge if isinstance(c, annotated_types.Ge) else nudge(c.gt, 1) if isinstance(c, annotated_types.Gt) else low
        high = c.le if isinstance(c, annotated_types.Le) else nudge(c.lt, -1) if isinstance(c, annotated_types.Lt) else high
    return float(low), float(high)


def calm(campaign: Campaign) -> Campaign:
    """``campaign`` without turbulence (and its turbulence's dispersions): the training flights of ``tune`` unless told.
    The gusts' white noise is drawn per period, so a change that adds or removes a period re-aligns every later gust:
    the landing point jumps (by ~50 m every ~4·10⁻⁸ of thrust scale on lynx_ballistic), and a derivative describes
    only the smooth piece it sits on. Measured on lynx_nominal_ctrl_1s (256 training flights, 12 steps): with the
    gusts the ellipse's area wandered from 3.74 to 3.52 km², without them it fell from 3.35 to 2.31 km²."""
    from .loader import with_overrides

    if campaign.config.environment.turbulence is None:
        return campaign
    values: dict = {f"dispersions.{path}": None for path in campaign.config.dispersions
                    if path.startswith("environment.turbulence.")}  # fmt: skip
    return with_overrides(campaign, values={**values, "environment.turbulence": None})


def tunable(campaign: Campaign) -> list[str]:
    """The numbers ``tune`` can adjust in ``campaign``: its canards' guidance numbers, its air brakes' gains."""
    gnc = campaign.config.gnc
    guidance = list(GUIDANCE_NUMBERS) if gnc is not None and gnc.canards else []
    return guidance + list(airbrake_numbers(campaign))


def check_parameters(campaign: Campaign, paths: Sequence[str]) -> None:
    """Raise ``ConfigError`` naming the first of ``paths`` that cannot be tuned: not a guidance number of this
    campaign's closed loop, nor a gain of its air brakes' law."""
    allowed = tunable(campaign)
    if not allowed:
        raise ConfigError("--params: the campaign has no canards ([gnc]) nor air brakes ([airbrakes]): no controller to tune")
    if not paths:
        raise ConfigError(f"--params: name at least one of {', '.join(allowed)}")
    for path in paths:
        if path not in allowed:
            raise ConfigError(f"--params {path}: not a tunable number of this campaign; tunable: {', '.join(allowed)}")
    check_inputs(campaign, paths)


@dataclasses.dataclass
class Tuning:
    """A tuning's record: the numbers tuned (``paths``), their values at each step (steps + 1, len(paths)) with the
    training objective there (``objective`` [its unit]) and the training flights that failed (``failed``);
    ``best``: the step whose objective was lowest, whose values are the result."""

    paths: list[str]
    objective_name: str
    values: np.ndarray
    objective: np.ndarray
    failed: np.ndarray
    seconds: np.ndarray
    train: int

    @property
    def best(self) -> int:
        return int(np.nanargmin(self.objective))

    @property
    def tuned(self) -> dict[str, float]:
        return dict(zip(self.paths, self.values[self.best].tolist()))


def tune(campaign: Campaign, paths: Sequence[str], objective: str, train: int, steps: int, learning_rate: float,
         apogee_target_m: float | None = None, turbulence: bool = False,
         progress: Callable[..., None] = lambda line, transient=False: None) -> Tuning:  # fmt: skip
    """Minimise ``objective`` over ``train`` training flights (``calm`` unless ``turbulence``) by ``steps`` Adam steps
    of ``learning_rate`` (in units of each number's starting size) on the guidance numbers ``paths``
    (``check_parameters``), each kept within ``bounds``; the objective is evaluated once more after the last step."""
    check_parameters(campaign, paths)
    campaign = campaign if turbulence else calm(campaign)
    settings = sim_settings(campaign)
    master_key = jax.random.key(campaign.config.seed + TRAINING_SEED_OFFSET)
    indices = jnp.arange(train, dtype=jnp.uint32)
    x0, flights = batch_function(campaign, settings, master_key, indices, paths, reverse=True)
    start = np.asarray(x0[0])
    scale = np.where(start != 0.0, np.abs(start), 1.0)
    low, high = (np.array(side) / scale for side in zip(*(bounds(path) for path in paths)))

    def loss(theta):
        outputs, (_, status) = flights(jnp.broadcast_to(theta * scale, x0.shape))
        return objective_value(objective, outputs, status, apogee_target_m), (status != 0).sum()

    gradient = jax.jit(jax.value_and_grad(loss, has_aux=True))
    optimizer = optax.adam(learning_rate)
    theta = jnp.asarray(start / scale)
    state = optimizer.init(theta)
    history: dict[str, list] = {"values": [], "objective": [], "failed": [], "seconds": []}
    progress(f"compiling the gradient of {objective} over {train} flights (about 2 minutes the first time)")
    for step in range(steps + 1):
        t0 = time.perf_counter()
        (value, failed), grad = gradient(theta)
        for name, item in zip(history, (np.asarray(theta) * scale, float(value), int(failed), time.perf_counter() - t0)):
            history[name].append(item)
        shown = ", ".join(f"{_section(path)[1]} {v:.4g}" for path, v in zip(paths, history["values"][-1]))
        progress(f"step {step}/{steps}: {objective} {float(value):.6g} ({int(failed)} failed) at {shown}", True)
        if step == steps or not np.all(np.isfinite(np.asarray(grad))):
            break
        with jax.numpy_dtype_promotion("standard"):  # optax mixes its int32 step count with floats
            updates, state = optimizer.update(grad, state, theta)
        theta = jnp.clip(optax.apply_updates(theta, updates), low, high)
    return Tuning(list(paths), objective, np.array(history["values"]), np.array(history["objective"]),
                  np.array(history["failed"]), np.array(history["seconds"]), train)  # fmt: skip


def _toml_value(value) -> str:
    return "[" + ", ".join(_toml_value(v) for v in value) + "]" if isinstance(value, list) else repr(value)


def rounded(values: dict[str, float], digits: int = 4) -> dict[str, float]:
    """``values`` to ``digits`` significant digits: what a tuned campaign file says."""
    return {path: float(f"{v:.{digits}g}") for path, v in values.items()}


def _config_section(config: CampaignConfig, section: str):
    return {"gnc.guidance": lambda: config.gnc.guidance, "airbrakes": lambda: config.airbrakes,
            "airbrakes.reference": lambda: config.airbrakes.reference_pi}[section]()  # fmt: skip


def tuned_campaign_text(campaign: Campaign, source: Path, out: Path, values: dict[str, float], comment: str) -> str:
    """A campaign file at ``out``, named as the file, that extends ``source`` (``campaign``'s file) with the tuned
    numbers ``values`` (``tunable``'s paths) in their sections, ``comment`` on top."""
    tables: dict[str, dict[str, object]] = {}
    for path, value in values.items():
        section, name, index = _section(path)
        table = tables.setdefault(section, {})
        if index:
            vector = table.setdefault(name, list(getattr(_config_section(campaign.config, section), name)))
            vector[int(index)] = value
        else:
            table[name] = value
    extends = Path(os.path.relpath(source.resolve(), out.resolve().parent)).as_posix()
    name = out.stem
    lines = [f"# {line}".rstrip() for line in comment.splitlines()]
    description = f"{campaign.config.description}; tuned by gradient ({', '.join(values)})"
    lines += [f"extends = {json.dumps(extends)}", f"name = {json.dumps(name)}", f"description = {json.dumps(description)}"]
    for section, table in tables.items():
        lines += ["", f"[{section}]", *(f"{key} = {_toml_value(value)}" for key, value in table.items())]
    return "\n".join(lines) + "\n"


def evaluate(campaign: Campaign, objective: str, n: int, apogee_target_m: float | None = None,
             chunk_size: int = 1000) -> dict:  # fmt: skip
    """``objective`` over the campaign's own first ``n`` realizations (its seed: held out from the training), flown
    forward as ``rocketmc run`` flies them; with the failed flights and the mean apogee [m] of the ok ones."""
    from .loader import with_overrides
    from .runner import run_chunks

    chunks = run_chunks(with_overrides(campaign, n_realizations=n), chunk_size=min(chunk_size, n))
    next(chunks)  # the compile time
    results = list(chunks)
    columns = {name: np.concatenate([r.outputs[name] for r in results]) for name in (*DIFFERENTIATED_OUTPUTS, "status")}
    outputs = np.stack([columns[name] for name in DIFFERENTIATED_OUTPUTS], axis=1)
    ok = columns["status"] == 0
    return {"value": float(objective_value(objective, outputs, columns["status"], apogee_target_m)),
            "failed": int((~ok).sum()), "apogee_mean_m": float(np.mean(columns["apogee_agl_m"][ok]))}  # fmt: skip


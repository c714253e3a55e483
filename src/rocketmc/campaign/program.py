"""A compiled flight program is built from a campaign's structure; its numbers are the program's arguments.

``program_numbers(campaign)`` splits off every floating-point number a flight reads from the campaign: the nominal
value of each dispersible field (``Campaign.nominal``), the thrust curve, the aerodynamic model's tables and
scalars, the measured wind profile, the day's atmosphere, the LQI gain schedule and the guidance reference.
``with_numbers(campaign, numbers)`` puts (traced) numbers back in their place. ``structure_fingerprint(campaign)``
hashes what is left: the configuration with each dispersible nominal value replaced by its sign (a zero switches an
error term off: ``model._channel``; the numbers fixed per campaign stay), the shapes and dtypes of the numbers and every other leaf of their trees, the
precision and the package versions. Two campaigns of one structure (another wind speed, mass, motor of as many
thrust points, N, seed) share one compiled program; a change of structure (a subsystem switched on, another table
shape, a number fixed per campaign such as a fin's span or the control period) compiles anew.

``tests/campaign/test_program.py`` lowers campaigns whose numbers all differ and checks that their programs are the
same text: a number read as a constant instead of an argument would show there.
"""

from __future__ import annotations

import dataclasses
import functools
import hashlib
import json
import os
import pickle
import tempfile
from collections.abc import Callable
from pathlib import Path

import jax
import numpy as np
from jax import export

from ..runtime import CACHE_DIR
from .fingerprint import fingerprint, setup
from .limits import fixed_reason
from .record import Campaign


def _parts(campaign: Campaign) -> tuple:
    """The trees of numbers a flight reads from the campaign, in ``with_numbers``'s order."""
    reference = None if campaign.gnc_inputs is None else campaign.gnc_inputs.reference
    return (campaign.nominal, campaign.thrust_time_s, campaign.thrust_n, campaign.aero, campaign.wind_profile,
            campaign.weather, campaign.gnc_schedule, reference, campaign.airbrakes)  # fmt: skip


def _is_number(leaf) -> bool:
    return isinstance(leaf, float | np.floating) or (isinstance(leaf, np.ndarray | jax.Array)
                                                      and np.issubdtype(leaf.dtype, np.floating))  # fmt: skip


def program_numbers(campaign: Campaign) -> list[np.ndarray]:
    """The campaign's numbers (``_parts``' floating-point leaves) as float arrays, in tree order."""
    return [np.asarray(leaf, dtype=float) for leaf in jax.tree_util.tree_leaves(_parts(campaign)) if _is_number(leaf)]


def with_numbers(campaign: Campaign, numbers) -> Campaign:
    """``campaign`` with its numbers (``program_numbers``' list, traced or not) put back."""
    leaves, tree = jax.tree_util.tree_flatten(_parts(campaign))
    given = iter(numbers)
    leaves = [next(given) if _is_number(leaf) else leaf for leaf in leaves]
    nominal, time_s, thrust_n, aero, wind, weather, schedule, reference, airbrakes = jax.tree_util.tree_unflatten(tree, leaves)
    inputs = None if campaign.gnc_inputs is None else campaign.gnc_inputs._replace(reference=reference)
    return dataclasses.replace(campaign, nominal=nominal, thrust_time_s=time_s, thrust_n=thrust_n, aero=aero,
                               wind_profile=wind, weather=weather, gnc_schedule=schedule, gnc_inputs=inputs,
                               airbrakes=airbrakes)  # fmt: skip


def _argument_paths(config: dict, nominal: dict[str, float]) -> dict:
    """The JSON config with each dispersible number the flight reads from its arguments (a float field whose path
    ``limits.fixed_reason`` lets be dispersed) replaced by its sign (-1, 0 or 1). Integers (counts), the numbers
    fixed per campaign (geometry, aerodynamic model, guidance, gain design, filters, sensor schedules: read as
    constants or at set-up) and the other sections keep their values."""
    for path, value in nominal.items():
        *parents, last = path.split(".")
        node = config
        for part in parents:
            node = node[int(part)] if isinstance(node, list) else node[part]
        key = int(last) if isinstance(node, list) else last
        if fixed_reason(path) is None and isinstance(node[key], float):
            node[key] = int(np.sign(value))
    return config


def structure_fingerprint(campaign: Campaign) -> str:
    """SHA-256 of what a compiled flight program depends on besides its arguments (see the module's docstring)."""
    flights = setup(campaign)
    leaves, tree = jax.tree_util.tree_flatten(_parts(campaign))
    described = [f"{np.asarray(leaf).dtype}{np.shape(leaf)}" if _is_number(leaf) else repr(leaf) for leaf in leaves]
    config = _argument_paths(json.loads(json.dumps(flights["config"])), campaign.nominal)
    return fingerprint({
        "config": {**config, "name": None, "description": None, "n_realizations": None, "seed": None},
        "numbers": {"tree": str(tree), "leaves": described},
        "precision": flights["precision"],
        "versions": flights["versions"],
    })  # fmt: skip


@dataclasses.dataclass(frozen=True)
class Program:
    """A program exported by ``cached_program``: ``call``, jitted from the export, takes and returns the leaves of
    the arguments and outputs (random keys as their data); ``out_tree`` rebuilds the outputs."""

    call: Callable
    out_tree: tuple  # (PyTreeDef, which output leaves are random keys)

    def lower(self, *args) -> jax.stages.Lowered:
        return self.call.lower(*_as_data(jax.tree_util.tree_leaves(args)))

    def compiled(self, *args) -> Callable:
        """Compiled now for arguments shaped as ``args``: a function of such arguments."""
        compiled, (tree, keys) = self.lower(*args).compile(), self.out_tree

        def run(*given):
            outputs = compiled(*_as_data(jax.tree_util.tree_leaves(given)))
            return jax.tree_util.tree_unflatten(tree, [jax.random.wrap_key_data(x) if k else x
                                                       for x, k in zip(outputs, keys)])  # fmt: skip

        return run


def _is_key(leaf) -> bool:
    return hasattr(leaf, "dtype") and jax.dtypes.issubdtype(leaf.dtype, jax.dtypes.prng_key)


def _as_data(leaves: list) -> list:
    return [jax.random.key_data(x) if _is_key(x) else x for x in leaves]


@functools.cache
def source_digest() -> str:
    """SHA-256 of rocketmc's Python files (~0.01 s, once per process): a program exported by other code (an editable
    install edited, a version that kept its number) is not read back as this code's."""
    package = Path(__file__).resolve().parents[1]
    digest = hashlib.sha256()
    for path in sorted(package.rglob("*.py")):
        digest.update(path.relative_to(package).as_posix().encode() + b"\0" + path.read_bytes())
    return digest.hexdigest()


def cached_program(name: str, key: str, function: Callable, *example_args, in_specs=None, out_spec=None) -> Program:
    """``function`` (jitted; pytrees in and out) through ``jax.export`` at the shapes of ``example_args``: read from the
    cache folder (``runtime.CACHE_DIR``: programs/NAME-HASH.jaxexport, the hash of ``key``, naming all the program
    depends on besides its arguments, of the arguments' tree and shapes and of rocketmc's code, ``source_digest``)
    where a process saved it, else traced now and saved there (written whole, then renamed: processes sharing the
    folder never read half a file). The ``Program`` is jitted from the export either way, hence the same bits.
    ``in_specs``: a PartitionSpec per argument and ``out_spec`` one for every output, over a mesh of the local devices
    (None: one device)."""
    leaves, in_tree = jax.tree_util.tree_flatten(example_args)
    in_keys = [_is_key(x) for x in leaves]
    shapes = [f"{x.dtype}{np.shape(x)}" if hasattr(x, "dtype") else type(x).__name__ for x in leaves]
    digest = fingerprint({"key": key, "tree": str(in_tree), "leaves": shapes, "devices": jax.local_device_count(),
                          "source": source_digest()})  # fmt: skip
    path = None if CACHE_DIR is None else Path(CACHE_DIR) / "programs" / f"{name}-{digest}.jaxexport"
    loaded = _load(path)
    if loaded is None:
        out_tree = []

        def flat(*leaves):  # random keys travel as their data: an export takes plain arrays
            given = [jax.random.wrap_key_data(x) if k else x for x, k in zip(leaves, in_keys)]
            outputs, tree = jax.tree_util.tree_flatten(function(*jax.tree_util.tree_unflatten(in_tree, given)))
            out_tree.append((tree, [_is_key(x) for x in outputs]))
            return [jax.random.key_data(x) if _is_key(x) else x for x in outputs]

        loaded = export.export(jax.jit(flat))(*_as_data(leaves)), out_tree[0]
        _save(path, loaded)
    exported, out_tree = loaded
    shardings = {}
    if in_specs is not None:
        mesh = jax.sharding.Mesh(np.array(jax.local_devices()), ("batch",))
        placed = lambda spec: jax.sharding.NamedSharding(mesh, spec)  # noqa: E731
        flat_specs = [placed(spec) for spec, arg in zip(in_specs, example_args) for _ in jax.tree_util.tree_leaves(arg)]
        shardings = {"in_shardings": tuple(flat_specs), "out_shardings": placed(out_spec)}
    return Program(jax.jit(exported.call, **shardings), out_tree)


def _load(path: Path | None):
    """(export, output tree) saved at ``path``; None if there is none or it cannot be read (another JAX's, cut
    short): made again."""
    if path is None or not path.exists():
        return None
    try:
        blob, out_tree = pickle.loads(path.read_bytes())  # the user's own cache folder, written by ``_save``
        return export.deserialize(bytearray(blob)), out_tree
    except (ValueError, TypeError, IndexError, EOFError, AttributeError, pickle.UnpicklingError):
        return None


def _save(path: Path | None, loaded) -> None:
    if path is None:
        return
    exported, out_tree = loaded
    path.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.NamedTemporaryFile(dir=path.parent, prefix=path.name, suffix=".tmp", delete=False) as file:
        file.write(pickle.dumps((exported.serialize(), out_tree)))
    os.replace(file.name, path)

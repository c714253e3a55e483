"""The fingerprint of a run's set-up: everything a realization's bits depend on, hashed.

``setup(campaign, chunk_size)`` is a JSON-able dict: the campaign text and its resolved
configuration (presets merged, the CLI's N, seed and aerodynamic model applied), a digest of the
numbers it read from files (thrust curve, aerodynamic tables, wind profile: built-in or the user's)
and of the LQI gains designed from them, the precision, the versions of rocketmc and of the numerical packages, and the chunk size.
``fingerprint(setup)`` is its SHA-256. A partial run's manifest, each of its chunk files and the
result file carry it; ``rocketmc run --resume`` and the gather accept only chunks of the same
fingerprint. Not covered: the kind of CPU (XLA compiles for the host's vector instructions), and
edits to rocketmc's code that leave its version unchanged (an editable install).
"""

from __future__ import annotations

import hashlib
import json
from importlib import metadata

import jax
import numpy as np

from ..runtime import PRECISION, __version__
from .record import Campaign

PACKAGES = ("jax", "jaxlib", "numpy", "scipy")
"""The packages whose versions can change a flight's bits, besides rocketmc."""


def data_digest(campaign: Campaign) -> str:
    """SHA-256 of every array the campaign read or built from files: its thrust curve, its
    aerodynamic model's tables and scalars, its wind profile, the day's atmosphere (its levels' arrays), and the
    LQI gain schedule designed from them (dtype, shape and bytes of each)."""
    digest = hashlib.sha256()
    weather = None if campaign.weather is None else campaign.weather[:5]
    tree = (campaign.thrust_time_s, campaign.thrust_n, campaign.aero, campaign.wind_profile, campaign.gnc_schedule,
            weather)  # fmt: skip
    digest.update(str(jax.tree_util.tree_structure(tree)).encode())
    for leaf in jax.tree_util.tree_leaves(tree):
        array = np.ascontiguousarray(leaf)
        digest.update(f"{array.dtype}{array.shape}".encode() + array.tobytes())
    return digest.hexdigest()


def setup(campaign: Campaign, chunk_size: int | None = None) -> dict:
    """What a run of ``campaign`` in chunks of ``chunk_size`` is, as a JSON-able dict; without a
    chunk size, what its flights are (what a compiled chunk function depends on)."""
    return {
        "campaign_toml": campaign.text,
        "config": json.loads(campaign.config.model_dump_json()),
        "files": campaign.files,
        "data_sha256": data_digest(campaign),
        "precision": PRECISION,
        "versions": {"rocketmc": __version__, **{name: metadata.version(name) for name in PACKAGES}},
        "chunk_size": chunk_size,
    }


def fingerprint(setup: dict) -> str:
    """SHA-256 of a ``setup`` dict (canonical JSON: sorted keys, no spaces)."""
    return hashlib.sha256(json.dumps(setup, sort_keys=True, separators=(",", ":")).encode()).hexdigest()


def differences(found: dict, expected: dict, prefix: str = "") -> list[str]:
    """Dotted paths where two set-ups differ (``config.rocket.aero.model``, ``precision``)."""
    if not (isinstance(found, dict) and isinstance(expected, dict)):
        return [] if found == expected else [prefix or "(all)"]
    paths = []
    for key in sorted(set(found) | set(expected), key=str):
        path = f"{prefix}.{key}" if prefix else str(key)
        if key not in found or key not in expected:
            paths.append(path)
        else:
            paths += differences(found[key], expected[key], path)
    return paths

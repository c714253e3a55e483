"""Shared fixtures of the physics tests.

Importing rocketmc first enables float64 in JAX for every test module (the tolerances below
assume double precision). Compiled flights are expensive (~15 s each on CPU), so the test modules
share them through module- or session-scoped fixtures and reuse one compilation for every
parameter set of the same pytree structure.
"""

from __future__ import annotations

import os
import shutil
import tempfile
from pathlib import Path

# The test processes (the two xdist workers, the CLI's subprocesses, the Dask workers) compile the same
# flight programs many times over; JAX's persistent compilation cache, in a folder of this test session
# that they all inherit through the environment, compiles each once. A cached program is the same
# executable, so no result changes. Set before JAX is imported, which reads it then.
_SESSION_CACHE = "JAX_COMPILATION_CACHE_DIR" not in os.environ
if _SESSION_CACHE:
    os.environ["JAX_COMPILATION_CACHE_DIR"] = tempfile.mkdtemp(prefix="rocketmc-tests-jax-cache-")
    # rocketmc's exported programs likewise (runtime.CACHE_DIR), not the user's cache folder
    os.environ["ROCKETMC_CACHE_DIR"] = os.path.join(os.environ["JAX_COMPILATION_CACHE_DIR"], "rocketmc")

import jax  # noqa: E402
import pytest

import rocketmc  # noqa: E402, F401  (enables jax_enable_x64)

# Every test runs under strict dtype promotion and with implicit rank promotion refused, so that
# a mixed-dtype or silently broadcast operation in the library fails the tests instead of passing.
jax.config.update("jax_numpy_dtype_promotion", "strict")
jax.config.update("jax_numpy_rank_promotion", "raise")

REPO = Path(__file__).resolve().parents[1]
CAMPAIGNS = REPO / "campaigns"


def movable(text: str) -> str:
    """A shipped campaign's text that loads from any folder: the campaign it extends named by its full path."""
    return text.replace('extends = "', f'extends = "{CAMPAIGNS}/')
MOTORS = REPO / "src" / "rocketmc" / "data" / "motors"


def pytest_configure(config):
    assert jax.config.jax_enable_x64, "rocketmc must enable float64 before the tests run"


def pytest_unconfigure(config):
    if _SESSION_CACHE:  # the process that made the folder (the xdist controller, or a serial run) removes it
        shutil.rmtree(os.environ["JAX_COMPILATION_CACHE_DIR"], ignore_errors=True)


@pytest.fixture(scope="session")
def lynx_campaign():
    """The Lynx campaign (drogue + main, three-layer wind, dispersions)."""
    from rocketmc.campaign import load_campaign

    return load_campaign(CAMPAIGNS / "lynx_nominal.toml")


@pytest.fixture(scope="session")
def lynx_params(lynx_campaign):
    """Nominal (undispersed) FlightParams of the Lynx campaign."""
    from rocketmc.campaign.model import nominal_params

    return nominal_params(lynx_campaign)


@pytest.fixture(scope="session")
def l1350_path():
    """The vendored Cesaroni 4263L1350-P RASP curve."""
    return MOTORS / "Cesaroni_4263L1350-P.eng"

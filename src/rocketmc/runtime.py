"""The process's runtime, set when rocketmc is first imported (docs/sharp-bits.md): two JAX options, the cores, the
cache of compiled programs and the version.

- float64 (``jax_enable_x64``): minutes of flight integrated in thousands of steps, and bit-reproducible campaigns,
  want it. ``ROCKETMC_PRECISION=float32`` in the environment (read at import) leaves x64 off, for measuring float32
  (``rocketmc bench --precision float32``);
- one XLA CPU device per core (``--xla_force_host_platform_device_count``), unless XLA_FLAGS already chooses, so a
  campaign chunk runs on every core. It only takes effect if JAX's backend has not started yet.
"""

import os

CORES = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1
"""The cores this process may run on."""
if "xla_force_host_platform_device_count" not in os.environ.get("XLA_FLAGS", ""):
    os.environ["XLA_FLAGS"] = f"{os.environ.get('XLA_FLAGS', '')} --xla_force_host_platform_device_count={CORES}".strip()


def _cache_dir() -> str | None:
    """``ROCKETMC_CACHE_DIR``, "off" for none, by default ``rocketmc`` in the user's cache folder."""
    chosen = os.environ.get("ROCKETMC_CACHE_DIR")
    if chosen is not None:
        return None if chosen.strip().lower() in ("", "off") else os.path.abspath(os.path.expanduser(chosen))
    if os.name == "nt":
        root = os.environ.get("LOCALAPPDATA") or os.path.expanduser("~\\AppData\\Local")
    else:
        root = os.environ.get("XDG_CACHE_HOME") or os.path.expanduser("~/.cache")
    return os.path.join(root, "rocketmc")


CACHE_DIR = _cache_dir()
"""The folder of compiled flight programs (``campaign.program``): the programs exported by structure
(``programs/``) and XLA's executables compiled from them (``xla/``, JAX's persistent compilation cache, unless
JAX_COMPILATION_CACHE_DIR already names one). Safe to delete at any time; ``ROCKETMC_CACHE_DIR`` moves it, or
turns it off with "off". A program loaded from it gives the same bits as one compiled anew."""

import jax  # noqa: E402

if CACHE_DIR is not None and not jax.config.jax_compilation_cache_dir:
    jax.config.update("jax_compilation_cache_dir", os.path.join(CACHE_DIR, "xla"))
    if "JAX_PERSISTENT_CACHE_MIN_COMPILE_TIME_SECS" not in os.environ:  # the set-up's ~90 small programs too: 3 s
        jax.config.update("jax_persistent_cache_min_compile_time_secs", 0.0)

PRECISION = os.environ.get("ROCKETMC_PRECISION", "float64")
"""``float64`` (the default) or ``float32``, from the environment variable ``ROCKETMC_PRECISION``."""
if PRECISION not in ("float64", "float32"):
    raise ValueError(f"ROCKETMC_PRECISION must be float64 or float32, got {PRECISION!r}")
jax.config.update("jax_enable_x64", PRECISION == "float64")

__version__ = "0.1.0"

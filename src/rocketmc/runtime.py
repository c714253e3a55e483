"""The process's runtime, set when rocketmc is first imported (docs/sharp-bits.md): two JAX options, the cores and
the version.

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

import jax  # noqa: E402

PRECISION = os.environ.get("ROCKETMC_PRECISION", "float64")
"""``float64`` (the default) or ``float32``, from the environment variable ``ROCKETMC_PRECISION``."""
if PRECISION not in ("float64", "float32"):
    raise ValueError(f"ROCKETMC_PRECISION must be float64 or float32, got {PRECISION!r}")
jax.config.update("jax_enable_x64", PRECISION == "float64")

__version__ = "0.1.0"

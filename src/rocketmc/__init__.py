"""rocketmc: a JAX Monte Carlo dispersion engine for sounding rockets with canard control.

Importing rocketmc sets the process's JAX options (``rocketmc.runtime``: float64, one XLA device per core). The
public API, each name imported from its module on first use (so ``import rocketmc`` loads JAX only)::

    import rocketmc as rmc
    campaign = rmc.with_overrides(rmc.load_campaign("campaigns/lynx_nominal.toml"), n_realizations=100)
    path = rmc.run_campaign(campaign, "results/lynx_nominal.h5")
    print(rmc.report(path))

- ``load_campaign(path)``, ``with_overrides(campaign, ...)``: a campaign file, checked, and the same with options
  changed (``Campaign``);
- ``run_campaign(campaign, out, ...)``: fly it into its HDF5 result file;
- ``load_run(path)``, ``summarize(run)``, ``report(run)``, ``plot_impacts(run, path)``, ``compare(runs)``: read,
  summarise, print, draw and compare result files;
- ``flight_record(campaign, realization)``: one flight's full time series;
- ``RocketmcError``: every error a user can act on, said in one line.
"""

import importlib

from .errors import RocketmcError as RocketmcError
from .runtime import CORES as CORES
from .runtime import PRECISION as PRECISION
from .runtime import __version__ as __version__

_API = {
    "Campaign": "campaign", "load_campaign": "campaign", "with_overrides": "campaign",
    "run_campaign": "campaign.run", "flight_record": "campaign.flights",
    "load_run": "analysis", "summarize": "analysis", "report": "analysis", "plot_impacts": "analysis",
    "compare": "analysis.compare",
}  # fmt: skip
"""The public names and the module (below ``rocketmc``) each comes from."""

__all__ = ["RocketmcError", "__version__", *_API]


def __getattr__(name: str):
    if name not in _API:
        raise AttributeError(f"module 'rocketmc' has no attribute {name!r}")
    value = getattr(importlib.import_module(f"{__name__}.{_API[name]}"), name)
    globals()[name] = value  # imported once
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *_API})

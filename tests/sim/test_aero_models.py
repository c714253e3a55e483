"""Both aerodynamic models fly the nominal Lynx to nearly the same apogee (docs/validation.md's acceptance)."""

from __future__ import annotations

import jax
import pytest

from rocketmc.aero import LinearAero, TableAero
from rocketmc.campaign import with_overrides
from rocketmc.campaign.model import nominal_params
from rocketmc.campaign.runner import sim_settings
from rocketmc.sim.flight import simulate_one
from rocketmc.sim.state import Status


def test_interpolated_and_simplified_apogees_within_2_percent(lynx_campaign):
    """The simplified model is the interpolated one linearised at zero angles; a nominal flight
    stays at small angles except on the rail and near apogee, so the apogees agree to ~0.6 %; the
    2 % bound is the project's acceptance (docs/validation.md)."""
    apogees = {}
    for model, kind in (("interpolated", TableAero), ("simplified", LinearAero)):
        campaign = with_overrides(lynx_campaign, aero_model=model)
        assert isinstance(campaign.aero, kind)
        summary, status = jax.jit(lambda p, c=campaign: simulate_one(p, sim_settings(c)))(nominal_params(campaign))
        assert int(status) == Status.OK
        apogees[model] = float(summary["apogee_agl_m"])
    assert apogees["simplified"] == pytest.approx(apogees["interpolated"], rel=0.02)
    # Measured 0.61 % (9.6 m): 1 % guards today's agreement (a deterministic model difference, not round-off).
    assert apogees["simplified"] == pytest.approx(apogees["interpolated"], rel=0.01)

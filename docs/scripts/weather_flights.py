"""The nominal (undispersed) Lynx of EuRoC 2021 in the standard atmosphere, calm (lynx_euroc_2021.toml), and
in the day's air of each weather campaign: apogee and impact point (docs/weather.md's table)."""

from pathlib import Path

import jax

from rocketmc.campaign import load_campaign
from rocketmc.campaign.model import nominal_params
from rocketmc.campaign.runner import sim_settings
from rocketmc.sim.flight import simulate_one

CAMPAIGNS = Path(__file__).parents[2] / "campaigns"

print(f"{'campaign':24} {'apogee_agl_m':>12} {'impact_north_m':>14} {'impact_east_m':>13} {'pad air (K, hPa)':>17}")
for name in ("lynx_euroc_2021", "lynx_euroc_era5", "lynx_euroc_era5_2025", "lynx_euroc_sounding"):
    campaign = load_campaign(CAMPAIGNS / f"{name}.toml")
    params = nominal_params(campaign)
    summary, status = jax.jit(lambda p: simulate_one(p, sim_settings(campaign)))(params)
    pad = params.environment.air(params.environment.site_altitude_m)
    print(f"{name:24} {float(summary['apogee_agl_m']):12.1f} {float(summary['impact_north_m']):14.1f} "
          f"{float(summary['impact_east_m']):13.1f} {float(pad.temperature):8.1f} {float(pad.pressure) / 100:7.1f}"
          f"  status {int(status)}")

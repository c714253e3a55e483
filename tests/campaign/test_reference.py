"""docs/campaign_reference.md is the schema's reference, regenerated."""

from __future__ import annotations

from rocketmc.campaign.limits import fixed_reason
from rocketmc.campaign.reference import INDEX, reference, rows, unit

from ..conftest import CAMPAIGNS, REPO


def test_the_committed_reference_is_the_generated_one():
    """Regenerate with `python -m rocketmc.campaign.reference > docs/campaign_reference.md`."""
    assert (REPO / "docs" / "campaign_reference.md").read_text() == reference()


def test_every_key_of_the_shipped_campaigns_is_in_the_reference():
    """Each number a dispersion could name in three shipped campaigns (presets, lists of tables and sensors
    included) has its row, which says "yes" exactly where the loader lets a dispersion draw it."""
    from rocketmc.campaign import load_campaign

    keys = {row[0]: row for row in rows()}
    for name in ("lynx_nominal.toml", "custom_rocket.toml", "lynx_nominal_ctrl_1s_sensors.toml"):
        campaign = load_campaign(CAMPAIGNS / name)
        for path in campaign.nominal:
            parts = path.split(".")
            generic = ".".join(INDEX if p.isdigit() else p for p in parts)
            key = generic if generic in keys else generic.rsplit(".", 1)[0]  # an element of a list of numbers
            assert key in keys, path
            fixed = fixed_reason(path) is not None
            assert keys[key][5] == "no (fixed per campaign)" if fixed else keys[key][5].startswith("yes"), (path, keys[key])


def test_units_follow_the_name_s_suffix():
    assert (unit("dry_inertia_kgm2"), unit("area_m2"), unit("speed_mps"), unit("delay_s"), unit("cd"),
            unit("roll_rate_limit_deg_s"), unit("bias_walk_deg_s2"), unit("vibration_per_kpa")) == \
        ("kg·m²", "m²", "m/s", "s", "", "deg/s", "deg/s²", "unit/kPa")  # fmt: skip

"""The navigation filters replayed on the real Roccaraso 2021 log (issue 18's acceptance): ``python
docs/scripts/navigate_roccaraso.py`` replays the log (``analysis.replay``, as ``rocketmc navigate``) with the site,
rail and [gnc.filters] tuning of data/campaigns/lynx_roccaraso_2021.toml (the thesis's tuning) and the variants of
``TUNINGS``, prints the estimates against the log's barometric height and GNSS velocity per window, and writes
docs/figures/roccaraso_navigate_*.png (the thesis's tuning and ``SHOWN``).

Windows (``replay.flight_windows``, seconds since liftoff): the coast from burnout to apogee, the descent from
apogee to landing, and the coast from ``REFERENCES_SETTLED_S``: before it both references are distorted (SOURCE.md:
the barometer from 2 to 5 s, by the flow over the static port near Mach 0.6; the GNSS velocity's direction is
visibly wrong until ~4.5 s, its receiver catching up after the 8 g boost: the flight-path angle dips to 50°).
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

import pandas as pd

from rocketmc.analysis import replay
from rocketmc.analysis.flight_log import ROCCARASO_2021, load_roccaraso_2021, reduce_flight
from rocketmc.analysis.sensor_log import read_sensor_log
from rocketmc.campaign import load_campaign
from rocketmc.campaign.model import filter_params

ROOT = Path(__file__).parents[2]
REFERENCES_SETTLED_S = 5.0
GNSS_STD = (5.0, 0.5)  # m, m/s: the NEO-M9N's open-sky accuracy, rounded up (its 0.05 m/s CEP is for still air)
TUNINGS = {
    "thesis, barometer off": {"barometer": False},
    "thesis, barometer on": {"barometer": True},
    "σ_b 200, barometer on": {"barometer": True, "field_direction_std": 200.0},
    "σ_b 200, baro, GNSS 5 m 0.5 m/s": {"barometer": True, "field_direction_std": 200.0, "gnss_after_s": 0.0,
                                        "gnss_std": GNSS_STD},
    "σ_b 200, baro, GNSS horizontal": {"barometer": True, "field_direction_std": 200.0, "gnss_after_s": 0.0,
                                       "gnss_std": GNSS_STD, "gnss": "horizontal"},
}  # fmt: skip
"""Label → ``replay.retuned``'s knobs over the thesis's tuning (GNSS on every axis but altitude, 500 m and 50 m/s
from 10.5 s, field direction σ_b 2); σ_b 200: the magnetometer all but ignored, the gyroscope trusted."""
SHOWN = ("thesis, barometer on", "σ_b 200, baro, GNSS 5 m 0.5 m/s")
ROWS = {
    "height − baro [m]": "height_{}_{}_m",
    "flight-path angle − GNSS [deg]": "gamma_{}_{}_deg",
    "heading − GNSS [deg]": "heading_{}_{}_deg",
    "body x to GNSS velocity [deg]": "body_to_velocity_{}_{}_deg",
}


def main() -> None:
    campaign = load_campaign(Path(str(resources.files("rocketmc") / "data" / "campaigns" / "lynx_roccaraso_2021.toml")))
    launch, site = campaign.config.launch, campaign.config.site
    log = read_sensor_log(ROCCARASO_2021)
    q_nb0 = replay.rail_attitude(launch.elevation_deg, launch.azimuth_deg)
    runs = {label: replay.replay(log, replay.retuned(filter_params(campaign), **knobs), q_nb0, site)
            for label, knobs in TUNINGS.items()}  # fmt: skip
    first = runs[next(iter(runs))]
    windows = replay.flight_windows(first, log)
    windows["coast from 5 s"] = (REFERENCES_SETTLED_S, windows["coast"][1])
    events = reduce_flight(load_roccaraso_2021())
    print(f"windows [s]: coast {windows['coast'][0]:.2f}-{windows['coast'][1]:.2f}, descent to {windows['descent'][1]:.2f} "
          f"(flight_log.reduce_flight: burnout {events.burnout_time_s:.2f}, apogee {events.apogee_time_s:.2f}, landing "
          f"shock {events.landing_time_s:.2f}); pad pressure {replay.pad_pressure(first):.1f} Pa")  # fmt: skip
    metrics = {label: replay.navigation_metrics(nav, log, windows) for label, nav in runs.items()}
    table = []
    for quantity, key in ROWS.items():
        for window in ("coast", "coast from 5 s", "descent") if quantity.startswith("height") else ("coast", "coast from 5 s"):
            row = {"quantity": quantity, "window": window}
            for label, m in metrics.items():
                row[label] = f"{m[key.format('rms', window)]:.1f} / {m[key.format('max', window)]:.1f}"
            table.append(row)
    pd.set_option("display.width", 250)
    print("RMS / max of each difference")
    print(pd.DataFrame(table).to_string(index=False))
    print("mean pitch − GNSS flight-path angle, coast from 5 s [deg]: "
          + ", ".join(f"{label} {m['pitch_minus_gamma_mean_coast from 5 s_deg']:+.1f}" for label, m in metrics.items()))
    paths = replay.plot_navigation({label: runs[label] for label in SHOWN}, log, windows, ROOT / "docs" / "figures",
                                   "Roccaraso 2021", prefix="roccaraso_")  # fmt: skip
    print("wrote " + ", ".join(str(p.relative_to(ROOT)) for p in paths))


if __name__ == "__main__":
    main()

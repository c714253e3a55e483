"""The build-up's zero-lift drag against OpenRocket's stored drag coefficient, on OpenRocket's example designs.

    python docs/scripts/openrocket_drag.py FOLDER [--out docs/figures/openrocket_drag.png]

Imports each design of FOLDER that rocketmc flies (``rocketmc import``, its first simulation with flight data), and
compares OpenRocket's stored "Drag coefficient" over the coast (burnout to apogee, motor off, angle of attack below
5°) with ``aero.drag.zero_lift_axial_coefficient`` of the imported geometry at the same Mach number and altitude,
both on OpenRocket's reference area (its largest body cross-section). Prints both at a few Mach numbers with
OpenRocket's friction, pressure and base parts beside the build-up's, and draws Cd(Mach) per design; then
OpenRocket's stored centre of pressure over the coast beside the build-up's (``aero.buildup.normal_force_slope``),
both from the nose tip.
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from rocketmc.aero.buildup import normal_force_slope
from rocketmc.aero.drag import drag_breakdown, zero_lift_axial_coefficient
from rocketmc.campaign import load_campaign
from rocketmc.campaign.loader import rocket_geometry
from rocketmc.campaign.openrocket import OpenRocketError, read_design, read_simulation
from rocketmc.campaign.openrocket_campaign import import_openrocket

MACH_POINTS = (0.05, 0.1, 0.2, 0.3)
"""Where the table compares the two (those a coast reaches)."""
MAX_ANGLE_OF_ATTACK_RAD = np.radians(5.0)
"""Coast samples above this angle of attack (near apogee) are left out: zero-lift drag is compared."""


def coast(design_path: Path, folder: Path) -> dict | None:
    """OpenRocket's coast (Mach, altitude [m], Cd and its parts) and the imported geometry of a design; None if
    rocketmc refuses it."""
    try:
        design = read_design(design_path)
    except OpenRocketError:
        return None
    index = next(k for k in range(1, len(design.simulations) + 1) if read_simulation(design, k).columns)
    sim = read_simulation(design, index)
    out = folder / f"{design_path.stem.replace(' ', '_')}.toml"
    import_openrocket(design_path, out, simulation=index, force=True)
    geometry = rocket_geometry(load_campaign(out).config.rocket)
    c = sim.columns
    burnout, apogee = min(sim.events.get("burnout", [0.0])), min(sim.events.get("apogee", [c["Time"][-1]]))
    keep = (c["Time"] > burnout) & (c["Time"] < apogee) & (np.abs(c["Angle of attack"]) < MAX_ANGLE_OF_ATTACK_RAD)
    order = np.argsort(c["Mach number"][keep])
    largest = max([geometry.body_diameter_m, *(d for t in geometry.sections() for d in (t.fore_diameter_m,
                                                                                         t.aft_diameter_m))])  # fmt: skip
    scale = geometry.reference_area_m2 / (np.pi * largest**2 / 4)  # ours onto OpenRocket's reference area
    parts = {name: c[f"{name} drag coefficient"][keep][order] for name in ("Friction", "Pressure", "Base")}
    return {"name": design_path.stem, "motor": design.motor_mount(sim.config_id).designation, "geometry": geometry,
            "scale": scale, "mach": c["Mach number"][keep][order], "altitude": c["Altitude"][keep][order],
            "cd": c["Drag coefficient"][keep][order], "parts": parts, "cp": c["CP location"][keep][order],
            "reference_length": float(c["Reference length"][0])}  # fmt: skip


def ours_parts(row: dict, mach: float, altitude: float) -> dict[str, float]:
    """The build-up's friction, pressure and base parts on OpenRocket's reference area."""
    terms = {k: v * row["scale"] for k, v in drag_breakdown(row["geometry"], mach, altitude).items()}
    friction = sum(v for k, v in terms.items() if k.startswith("friction"))
    return {"Friction": friction, "Base": terms["base"], "Pressure": terms["total"] - friction - terms["base"],
            "total": terms["total"]}  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folder", help="a folder of OpenRocket designs (.ork)")
    parser.add_argument("--out", default="docs/figures/openrocket_drag.png")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        rows = [r for p in sorted(Path(args.folder).glob("*.ork")) if (r := coast(p, Path(folder))) is not None]
    print("| design (motor) | Mach | OpenRocket Cd (friction + pressure + base) | rocketmc Cd (friction + pressure + base) |")
    print("|---|---|---|---|")
    for row in rows:
        for mach in MACH_POINTS:
            if not row["mach"][0] <= mach <= row["mach"][-1]:
                continue
            theirs = {k: float(np.interp(mach, row["mach"], v)) for k, v in row["parts"].items()}
            cd = float(np.interp(mach, row["mach"], row["cd"]))
            ours = ours_parts(row, mach, float(np.interp(mach, row["mach"], row["altitude"])))
            print(f"| {row['name']} ({row['motor']}) | {mach:g} | {cd:.3f} ({theirs['Friction']:.3f} + "
                  f"{theirs['Pressure']:.3f} + {theirs['Base']:.3f}) | {ours['total']:.3f} ({ours['Friction']:.3f} + "
                  f"{ours['Pressure']:.3f} + {ours['Base']:.3f}) |")  # fmt: skip
    print("\n| design | Mach | OpenRocket CP [m from the tip] | rocketmc CP | difference [calibers] |")
    print("|---|---|---|---|---|")
    for row in rows:
        mach = float(np.median(row["mach"]))
        theirs = float(np.interp(mach, row["mach"], row["cp"]))
        ours = float(normal_force_slope(row["geometry"], mach)[1])
        print(f"| {row['name']} | {mach:.2f} | {theirs:.3f} | {ours:.3f} | "
              f"{(ours - theirs) / row['reference_length']:+.2f} |")  # fmt: skip
    figure = Figure(figsize=(7, 4.5), layout="constrained")
    ax = figure.subplots()
    for i, row in enumerate(rows):
        color = f"C{i}"
        ax.plot(row["mach"], row["cd"], ".", color=color, markersize=3, label=f"{row['name']}: OpenRocket (stored)")
        ours = zero_lift_axial_coefficient(row["geometry"], row["mach"], row["altitude"]) * row["scale"]
        ax.plot(row["mach"], ours, "-", color=color, label="rocketmc build-up")
    ax.set(xlabel="Mach number", ylabel="zero-lift drag coefficient (OpenRocket's reference area)",
           title="Coast drag of OpenRocket's example designs")  # fmt: skip
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, ncols=2)
    figure.savefig(args.out, dpi=130)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()

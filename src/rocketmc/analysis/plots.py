"""Plots of campaign results (north/east in metres from the pad, NED world frame)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from ..files import replacing
from .ellipse import confidence_ellipse
from .results import Run

_ELLIPSE_COLORS = ("tab:green", "tab:orange", "tab:red", "tab:purple", "tab:brown")


def _area_label(area_m2: float) -> str:
    """Area in km^2 (m^2 below 0.01 km^2)."""
    if area_m2 >= 1e4:
        return f"{area_m2 / 1e6:.3g} km²"
    return f"{area_m2:.3g} m²"


def plot_impacts(
    run: Run,
    path: str | Path | None = None,
    ax: Axes | None = None,
    levels=(0.5, 0.95, 0.99),
) -> Figure:
    """Impact points of ok realizations with their confidence ellipses.

    East [m] on the x axis, north [m] on the y axis, equal aspect; the pad (origin) and the
    mean impact point are marked. Failed realizations are not drawn but counted in the title;
    ellipses are omitted when fewer than 3 ok impact points exist. Draws on ``ax`` if given
    (else on a new figure, without pyplot) and saves to ``path`` (PNG at 150 dpi) if given.
    """
    if ax is None:
        fig = Figure(figsize=(7.5, 7.5), layout="constrained")
        ax = fig.add_subplot()
    else:
        fig = ax.figure
    north, east = run.ok_impacts()
    n_total = len(run.outputs)
    n_ok = int(run.ok.sum())

    alpha = float(np.clip(300.0 / max(north.size, 1), 0.15, 0.8))
    ax.scatter(east, north, s=6, color="tab:blue", alpha=alpha, linewidths=0, label="impacts")
    ax.plot(0.0, 0.0, "k^", markersize=10, label="pad", zorder=4)
    if north.size >= 3:
        for i, level in enumerate(levels):
            e = confidence_ellipse(north, east, level)
            b_north, b_east = e.boundary()
            ax.plot(
                b_east,
                b_north,
                color=_ELLIPSE_COLORS[i % len(_ELLIPSE_COLORS)],
                linewidth=1.8,
                label=f"{100 * level:g} % ellipse ({_area_label(e.area_m2)})",
                zorder=3,
            )
        ax.plot(east.mean(), north.mean(), "kX", markersize=9, label="mean impact", zorder=4)

    title = f"{run.attrs.get('campaign_name', '')}: impact points, {n_ok} ok / {n_total}"
    if n_ok < n_total:
        title += f"\n({n_total - n_ok} failed realizations not shown)"
    ax.set_title(title)
    ax.set_xlabel("east of pad [m]")
    ax.set_ylabel("north of pad [m]")
    ax.set_aspect("equal", adjustable="datalim")
    ax.grid(True, alpha=0.4)
    legend = ax.legend(loc="best", fontsize="small", framealpha=0.9)
    for handle in legend.legend_handles:  # faint scatter points stay visible in the legend
        handle.set_alpha(1.0)
    if path is not None:
        with replacing(path) as partial:  # a full disk leaves no half-written figure
            fig.savefig(partial, dpi=150, format=Path(path).suffix.lstrip(".").lower() or "png")
    return fig

"""Figures of single hard cases beyond the stability figure (``figures.hard_stability``)."""

from __future__ import annotations

import pandas as pd
from matplotlib.figure import Figure

NITSCHE_CAPTION = ("Nitsche's method on free-boundary (2112 DOFs) against gamma_0 for theta = "
                   "1, 0, -1 (semismooth Newton): penetration, energy error and pressure error "
                   "against the exact solution; a missing point is a failed solve (the "
                   "symmetric variant below its coercivity bound).")


def nitsche_parameters(hard: pd.DataFrame):
    """The ``nitsche-gamma`` sweep: three panels against gamma_0, one line per theta."""
    sweep = hard[(hard["case"] == "nitsche-gamma") & (hard["solver"] == "active-set")]
    if sweep.empty or "gamma_0" not in sweep:
        return None
    fig = Figure(figsize=(13, 4))
    axes = fig.subplots(1, 3)
    for theta, group in sweep.groupby("theta", sort=False):
        ok = group[group["verdict"] != "failed"]
        for ax, column in zip(axes, ("penetration", "energy_error", "pressure_error"),
                              strict=True):
            ax.loglog(ok["gamma_0"], ok[column].clip(lower=1e-17), marker="o",
                      label=f"theta = {theta:g}")
    for ax, title in zip(axes, ("max penetration", "energy error (exact)",
                                "pressure error (exact)"), strict=True):
        ax.set(xlabel="gamma_0", title=f"nitsche: {title}")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
        ax.title.set_fontsize(10)
    fig.tight_layout()
    return fig

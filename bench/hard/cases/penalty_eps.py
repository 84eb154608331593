"""The penalty with eps_0 = 1e-1 .. 1e-12: penetration, conditioning and the reference
solver's accuracy (docs/theory.md, section 8)."""

from __future__ import annotations

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from bench.hard.registry import case_figure, hard_case
from bench.hard.verdicts import PRESSURE_TOLERANCE, solve_both
from formulations.solvers.registry import FAST_SOLVER
from scenes import get_scene

EPSILONS_0 = (1e-1, 1e-2, 1e-4, 1e-6, 1e-8, 1e-10, 1e-12)


@hard_case("penalty-eps", "penalty with eps_0 = 1e-1 .. 1e-12 on the paper scene: penetration, "
                          "conditioning, and the reference solver's accuracy")
def penalty_sweep() -> list[dict]:
    scene, records = get_scene("paper"), []
    mesh = scene.mesh.refined(3)
    for eps in EPSILONS_0:
        rows, _ = solve_both("penalty-eps", scene, "penalty", mesh, variant=f"eps_0={eps:g}",
                             level=3, epsilon_0=eps)
        for row in rows:
            row["finding"] = f"nodal penetration {row['nodal_penetration']:.2e}" + (
                f", condition {row['condition_estimate']:.2e}"
                if np.isfinite(row["condition_estimate"]) else "")
        records += rows
    return records


@case_figure("penalty-eps", "The penalty against eps_0: penetration and condition estimate "
                            "(fast solver), and each solver's pressure loss with the bar for "
                            "'accurate'.")
def penalty_figure(rows: pd.DataFrame):
    fig = Figure(figsize=(10, 4))
    axes = fig.subplots(1, 2)
    fast = rows[rows["solver"] == FAST_SOLVER]
    eps = fast["variant"].str.split("=").str[1].astype(float)
    axes[0].loglog(eps, fast["nodal_penetration"], marker="o", label="max nodal penetration")
    axes[0].loglog(eps, fast["condition_estimate"], marker="s", label="condition estimate")
    axes[0].set(xlabel="eps_0", title=f"penalty ({FAST_SOLVER}): penetration, conditioning")
    for solver, group in rows.groupby("solver"):
        axes[1].loglog(group["variant"].str.split("=").str[1].astype(float),
                       group["pressure_loss"].clip(lower=1e-17), marker="o", label=solver)
    axes[1].axhline(PRESSURE_TOLERANCE, color="k", linewidth=0.7, linestyle="--",
                    label="bar for 'accurate'")
    axes[1].set(xlabel="eps_0", title="penalty: pressure loss")
    for ax in axes:
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
        ax.title.set_fontsize(10)
        ax.invert_xaxis()
    fig.tight_layout()
    return fig

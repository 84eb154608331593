"""Nitsche's method over eight decades of gamma_0 for each variant theta = 1, 0, -1: where the
symmetric variant loses coercivity and Newton fails while the skew-symmetric one does not, with
the penetration, the pressure error and the energy error against the exact solution
(docs/theory.md, section 12.5)."""

from __future__ import annotations

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from bench.hard.registry import case_figure, hard_case
from bench.hard.verdicts import solve_both
from bench.measure.contact import penetration
from bench.truth.kinds import ExactTruth
from formulations import STATUS_FAILED
from formulations.solvers.registry import FAST_SOLVER
from scenes import get_scene

GAMMAS_0 = tuple(10.0 ** k for k in range(-4, 5))
THETAS = (1.0, 0.0, -1.0)
LEVEL = 3  # 2112 DOFs on free-boundary: every gamma_0 and theta in a few seconds


@hard_case("nitsche-gamma", "Nitsche with gamma_0 = 1e-4 .. 1e4 for theta = 1, 0, -1 on the "
                            "exact free-boundary scene: coercivity, Newton, penetration, errors")
def nitsche_sweep() -> list[dict]:
    scene = get_scene("free-boundary")
    truth, mesh, records = ExactTruth(scene), scene.mesh.refined(LEVEL), []
    for theta in THETAS:
        for gamma_0 in GAMMAS_0:
            rows, solutions = solve_both("nitsche-gamma", scene, "nitsche", mesh,
                                         variant=f"theta={theta:g}:gamma_0={gamma_0:g}",
                                         level=LEVEL, theta=theta, gamma_0=gamma_0)
            for row, sol in zip(rows, solutions, strict=True):
                row.update(theta=theta, gamma_0=gamma_0, energy_error=np.nan,
                           pressure_error=np.nan)
                if sol.status == STATUS_FAILED:
                    row["finding"] = sol.reason
                    continue
                errors = truth.errors(sol)
                row.update(energy_error=errors.energy_error,
                           pressure_error=errors.pressure_error,
                           penetration=penetration(scene, sol, nodal=True))
                row["finding"] = (f"penetration {row['penetration']:.2e}, energy error "
                                  f"{errors.energy_error:.2e}, pressure error "
                                  f"{errors.pressure_error:.2e}, {sol.iterations} iterations")
            records += rows
    return records


@case_figure("nitsche-gamma", "Nitsche's method on free-boundary (2112 DOFs) against gamma_0 for "
                              "theta = 1, 0, -1 (semismooth Newton): penetration, energy error "
                              "and pressure error against the exact solution; a missing point "
                              "is a failed solve (the symmetric variant below its coercivity "
                              "bound).")
def nitsche_figure(rows: pd.DataFrame):
    """Three panels against gamma_0, one line per theta."""
    sweep = rows[rows["solver"] == FAST_SOLVER]
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

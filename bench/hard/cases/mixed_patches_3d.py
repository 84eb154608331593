"""The mixed method on tetrahedra with star patches (h/H <= 1/2) and with the contact triangles
(h/H = 1) as its multiplier mesh: the discrete inf-sup constant under uniform refinement
(docs/theory.md, section 14.7)."""

from __future__ import annotations

import pandas as pd

from bench.hard.cases.mixed_ratio import inf_sup_plot
from bench.hard.registry import case_figure, hard_case
from bench.hard.verdicts import solve_both
from formulations.solvers.registry import FAST_SOLVER
from scenes import get_scene

PATCHES = {"star": 0.5, "triangle": 1.0}  # variant -> h_over_H
LEVELS = (0, 1, 2)  # paper-3d, P1: 300, 1944, 13 872 DOFs


@hard_case("mixed-patches-3d", "mixed method on paper-3d with star patches (h/H <= 1/2) and the "
                               "contact triangles (h/H = 1): discrete inf-sup constant under "
                               "refinement", meta={"seconds": 26})  # measured on 2 cores
def mixed_patches_3d() -> list[dict]:
    scene, records = get_scene("paper-3d"), []
    for variant, ratio in PATCHES.items():
        for level in LEVELS:
            rows, _ = solve_both("mixed-patches-3d", scene, "mixed", scene.mesh.refined(level),
                                 variant=variant, level=level, inf_sup=True, h_over_H=ratio)
            records += rows
    frame = pd.DataFrame(records)
    for variant in PATCHES:
        part = frame[(frame["variant"] == variant) & (frame["solver"] == FAST_SOLVER)]
        beta = part["inf_sup"].to_numpy()
        text = f"beta_h {', '.join(f'{b:.3g}' for b in beta)} at {part['ndofs'].iloc[0]}.." \
               f"{part['ndofs'].iloc[-1]} DOFs"
        if beta[-2] > 0:  # levelling off (stable) or halving with h (unstable)
            text += f"; last refinement x{beta[-1] / beta[-2]:.2f}"
        for record in records:
            if record["variant"] == variant:
                record["finding"] = text
    return records


@case_figure("mixed-patches-3d", "The 3D mixed method's discrete inf-sup constant beta_h against "
                                "ndofs for star patches and for the contact triangles (whose "
                                "beta_h is 0: the linear axis shows it).")
def patches_figure(rows: pd.DataFrame):
    return inf_sup_plot(rows, "mixed on paper-3d: discrete inf-sup constant beta_h",
                        log_beta=False)

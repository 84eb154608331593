"""The mixed method on tetrahedra with its multiplier spaces: continuous P1 on the surface one
level coarser (the default for P1) and on the contact triangles, piecewise constant on the
coarse triangles, on vertex stars and on the contact triangles: the discrete inf-sup constant
under uniform refinement (docs/theory.md, sections 14.7 and 19.2)."""

from __future__ import annotations

import pandas as pd

from bench.hard.cases.mixed_ratio import inf_sup_plot
from bench.hard.registry import case_figure, hard_case
from bench.hard.verdicts import solve_both
from formulations.solvers.registry import FAST_SOLVER
from scenes import get_scene

# variant -> the multiplier space's options (formulations.methods.mixed_surface)
PATCHES = {"coarse P1": dict(multiplier_degree=1, h_over_H=0.5),
           "trace P1": dict(multiplier_degree=1, h_over_H=1.0),
           "coarse P0": dict(multiplier_degree=0, h_over_H=0.5),
           "star": dict(multiplier_mesh="star", h_over_H=0.5),
           "triangle": dict(multiplier_degree=0, h_over_H=1.0)}
LEVELS = (0, 1, 2)  # paper-3d, P1: 300, 1944, 13 872 DOFs


@hard_case("mixed-patches-3d", "mixed method on paper-3d with P1 multipliers on the coarse "
                               "surface and on the contact triangles, P0 on coarse triangles, "
                               "stars and triangles: discrete inf-sup constant under "
                               "refinement", meta={"seconds": 28})  # measured on 2 cores
def mixed_patches_3d() -> list[dict]:
    scene, records = get_scene("paper-3d"), []
    for variant, options in PATCHES.items():
        for level in LEVELS:
            rows, _ = solve_both("mixed-patches-3d", scene, "mixed", scene.mesh.refined(level),
                                 variant=variant, level=level, inf_sup=True, **options)
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

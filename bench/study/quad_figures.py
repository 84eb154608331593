"""The seed's Figures 1 and 2 on its own element: the adaptive Q1 mesh with its hanging nodes
and the von Mises stress on the deformed body (Fig. 1), and the estimated error under uniform
and adaptive refinement with the slopes marked (Fig. 2) (docs/theory.md, section 15).
``matplotlib.figure.Figure`` objects, no pyplot state."""

from __future__ import annotations

import numpy as np
import pandas as pd
from matplotlib.collections import PolyCollection
from matplotlib.figure import Figure

from bench.measure.slope import fit_slope
from bench.report.figures import VON_MISES_PERCENTILE, _slope_triangle
from bench.sequence.marking import mark
from estimators.quad_residual import QuadStress, quad_residual_estimate
from formulations.elasticity import von_mises
from formulations.quad_mixed import solve_quad_mixed
from scenes import get_scene
from scenes.quad_hierarchy import QuadHierarchy


def adaptive_solution(scene_name: str, max_dofs: int, theta: float = 0.5):
    """The last level within ``max_dofs`` of the seed's setup: Q1, the mixed method with
    lambda_H one level coarser, residual estimator, Doerfler marking."""
    from bench.study.quads import tensor_grid

    scene = get_scene(scene_name)
    hierarchy, last = QuadHierarchy.from_tensor(*tensor_grid(scene)), None
    while True:
        solution = solve_quad_mixed(scene, hierarchy, 1)
        if solution.elasticity.ndofs > max_dofs:
            return scene, last
        last = (hierarchy, solution)
        estimate = quad_residual_estimate(scene, solution)
        hierarchy = hierarchy.refined(mark(estimate.indicators, "doerfler", theta))


def mesh_and_stress(scene_name: str = "paper", max_dofs: int = 20000) -> Figure:
    """Fig. 1: the adaptive mesh (hanging nodes in red) and von Mises on the deformed body."""
    scene, (hierarchy, solution) = adaptive_solution(scene_name, max_dofs)
    mesh = solution.elasticity.basis.mesh
    cells = mesh.p[:, mesh.t].transpose(2, 1, 0)  # (nE, 4, 2)
    fig = Figure(figsize=(11, 5))
    left, right = fig.subplots(1, 2)
    left.add_collection(PolyCollection(cells, facecolors="none", edgecolors="k",
                                       linewidths=0.2))
    hanging = hierarchy.p[:, hierarchy.hanging()[0]]
    left.plot(hanging[0], hanging[1], "r.", markersize=2,
              label=f"{hanging.shape[1]} hanging nodes")
    left.set_title(f"{scene_name}: adaptive Q1 mesh, {solution.elasticity.ndofs} DOFs, "
                   f"{mesh.t.shape[1]} cells", fontsize=9)
    left.legend(loc="upper right", fontsize=7)
    stress = QuadStress(solution)
    centres = mesh.p[:, mesh.t].mean(axis=1)
    sigma = stress.sigma(centres, np.arange(mesh.t.shape[1]))
    vm = von_mises(np.array([sigma[0, 0], sigma[1, 1], sigma[0, 1]]))
    top = np.percentile(vm, VON_MISES_PERCENTILE)
    u = solution.u[solution.elasticity.basis.nodal_dofs]
    scale = 0.1 * np.ptp(mesh.p, axis=1).max() / max(np.abs(u).max(), 1e-300)
    scale = 10 ** np.floor(np.log10(scale)) if scale < 1 else 1.0
    moved = (mesh.p + scale * u)[:, mesh.t].transpose(2, 1, 0)
    art = right.add_collection(PolyCollection(moved, array=np.minimum(vm, top), cmap="viridis",
                                              edgecolors="face", linewidths=0.2))
    fig.colorbar(art, ax=right, label=f"von Mises (clipped at its {VON_MISES_PERCENTILE:g}th "
                                      f"percentile = {top:.4g})")
    right.set_title(f"von Mises on the deformed body, displacement x {scale:g}", fontsize=9)
    for ax in (left, right):
        ax.autoscale()
        ax.set_aspect("equal")
    fig.tight_layout()
    return fig


def estimated_error(table: pd.DataFrame, scene_name: str = "paper",
                    method: str = "mixed") -> Figure:
    """Fig. 2: eta and the error against the DOFs, uniform and adaptive, of the lowest order in
    the table (Q1 when it has it), with the fitted slopes in the legend and the slopes -1/4
    (the seed's O(h^1/2)) and -1/2 (O(h)) drawn."""
    fig = Figure(figsize=(6.5, 5))
    ax = fig.subplots()
    rows = table[(table["scene"] == scene_name) & (table["method"] == method)]
    order = int(rows["order"].min()) if len(rows) else 1  # Q1 when the study has it
    rows = rows[rows["order"] == order]
    for strategy, style in (("uniform", "o-"), ("adaptive", "s-")):
        group = rows[rows["strategy"] == strategy].sort_values("ndofs")
        if len(group) < 2:
            continue
        for column, name, alpha in (("eta", "eta", 1.0), ("energy_error", "error", 0.5)):
            good = group[np.isfinite(group[column]) & (group[column] > 0)]
            if len(good) < 2:
                continue
            slope = fit_slope(good["ndofs"], good[column]).slope
            ax.loglog(good["ndofs"], good[column], style, markersize=3, alpha=alpha,
                      label=f"{name}, {strategy} (slope {slope:.2f})")
    if not rows.empty:
        x0, y0 = rows["ndofs"].min() * 3, rows["eta"].max() / 3
        _slope_triangle(ax, x0, y0, -0.25, "-1/4: O(h^1/2)")
        _slope_triangle(ax, x0, y0 / 10, -0.5, "-1/2: O(h)")
    ax.set_xlabel("DOFs N")
    ax.set_ylabel("energy norm")
    ax.set_title(f"{scene_name}, Q{order}, {method}: estimated and true error", fontsize=9)
    ax.legend(fontsize=7, loc="lower left")
    fig.tight_layout()
    return fig

"""The seed's mixed method on a quadrilateral hierarchy: Q1 or Q2 displacements, the contact
pressure lambda_H >= 0 piecewise constant on the edges of a coarser level of the same
hierarchy along Gamma_C (the seed's T_CH; docs/theory.md, sections 3 and 15).

A coarse edge is the Gamma_C edge of a leaf's ancestor ``levels_up`` levels above it; it holds
the leaf edges below it (two for one level up on a uniform mesh: h/H = 1/2; four for two).
Row g of B is int_{E_g} u_h . n ds (Newton-Cotes on each leaf edge, exact for Q1 and Q2
traces), G_g = int_{E_g} g ds (Gauss-Legendre). B' mu = sum_g mu_g int_{E_g} phi . n ds, so the
multiplier of row g is lambda_H on E_g itself, and mu_g |E_g| the force on E_g.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import sparse

from formulations.base import ContactQP
from formulations.contact import gauss_legendre
from formulations.elasticity import assemble_elasticity
from formulations.quad_vi import SIMPSON, QuadContactSolution, contact_edges, failed
from formulations.solvers.registry import FAST_SOLVER, SOLVERS
from scenes import Scene
from scenes.quad_hierarchy import QuadHierarchy, coarse_edges


@dataclass(frozen=True, eq=False)
class QuadMixedProblem:
    """The mixed method's QP on a hierarchy's leaves, and what recovers its solution: the
    contact edges, each one's coarse edge (``group``) and the coarse edges' lengths ``H``;
    ``multiplier_gram`` is H^2, the Gram matrix of ||mu||_{-1/2,h}^2 = sum_g H_g ||mu||_{0,E_g}^2
    (formulations.diagnostics)."""

    elasticity: object
    edges: object
    group: np.ndarray
    H: np.ndarray
    qp: ContactQP

    @property
    def multiplier_gram(self) -> np.ndarray:
        return self.H**2


def mixed_problem(scene: Scene, hierarchy: QuadHierarchy, order: int = 1,
                  levels_up: int = 1) -> QuadMixedProblem:
    """Assemble the mixed method with lambda_H on the coarse edges ``levels_up`` levels above
    the leaves (module docstring)."""
    elasticity = assemble_elasticity(scene, hierarchy.mesh(), order)
    basis, mesh = elasticity.basis, elasticity.basis.mesh
    edges = contact_edges(scene, elasticity)
    facets, a, b, length = edges.facets, edges.a, edges.b, edges.length
    group = coarse_edges(hierarchy, edges.cells, edges.normal, levels_up)
    weights = [np.full(2, 0.5)] if order == 1 else [SIMPSON[[0, 2]], SIMPSON[1:2]]
    dofs = [mesh.facets[:, facets]] if order == 1 else [mesh.facets[:, facets],
                                                        facets[None, :]]
    rows, cols, values = [], [], []
    for w, nodes, table in zip(weights, dofs, (basis.nodal_dofs, basis.facet_dofs),
                               strict=False):
        for k in range(nodes.shape[0]):
            for c in range(2):
                rows.append(group)
                cols.append(table[c, nodes[k]])
                values.append(w[k] * length * edges.normal[c])
    m = int(group.max()) + 1 if group.size else 0
    B = sparse.csr_matrix((np.concatenate(values) if values else np.zeros(0),
                           (np.concatenate(rows) if rows else np.zeros(0, int),
                            np.concatenate(cols) if cols else np.zeros(0, int))),
                          shape=(m, basis.N))
    t, w = gauss_legendre(4)
    points = a[:, :, None] + (b - a)[:, :, None] * t
    G = np.bincount(group, (np.asarray(scene.gap(points)) * w).sum(axis=1) * length, m)
    H = np.bincount(group, length, m)
    qp = ContactQP(K=elasticity.K_free, F=elasticity.F_free, B=elasticity.restrict(B), G=G,
                   row_scale=H,
                   objective_scale=float(scene.material.young_modulus),
                   near_null=elasticity.rigid_modes)
    return QuadMixedProblem(elasticity, edges, group, H, qp)


def solve_quad_mixed(scene: Scene, hierarchy: QuadHierarchy, order: int = 1,
                     levels_up: int = 1, solver: str = FAST_SOLVER,
                     **options) -> QuadContactSolution:
    """The mixed method with lambda_H on the coarse edges ``levels_up`` levels above the
    leaves; the reactions of the solution are the forces lambda_H |E_g| on the coarse
    edges."""
    problem = mixed_problem(scene, hierarchy, order, levels_up)
    elasticity, edges, qp = problem.elasticity, problem.edges, problem.qp
    answer = SOLVERS.get(solver)(qp, **options)
    if answer.u is None or answer.multipliers is None or not np.all(np.isfinite(answer.u)):
        return failed(elasticity, edges, problem.H.size, answer, 1)
    energy = float(0.5 * answer.u @ (qp.K @ answer.u) - qp.F @ answer.u)
    pressure = np.maximum(answer.multipliers, 0.0)  # lambda_H on each coarse edge
    return QuadContactSolution(elasticity, elasticity.expand(answer.u), pressure * problem.H,
                               energy, answer.status, answer.reason, edges,
                               pressure[problem.group][:, None])

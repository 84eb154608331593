"""The primal variational inequality ``vi`` on a quadrilateral hierarchy (Q1, Q2): nodal
constraints u_h(x_i) . n_i <= g(x_i) at every Lagrange node of Gamma_C (its vertices, and for
Q2 its edge midpoints), posed on the conforming space of ``formulations.quad_elasticity``
(docs/theory.md, sections 3 and 15).

Nodes on Gamma_C are never hanging (an edge on the boundary has one cell), so each row is
n_i' at the node's two cell DOFs, taken to the conforming space by P. The multiplier of row i
is the nodal contact reaction, as in ``formulations.vi``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import sparse

from formulations.base import ContactQP
from formulations.quad_elasticity import (
    QuadElasticity,
    assemble_quad_elasticity,
    boundary_facets_of,
)
from formulations.solvers.registry import FAST_SOLVER, SOLVERS
from scenes import Scene
from scenes.quad_hierarchy import QuadHierarchy


@dataclass(frozen=True, eq=False)
class QuadContactSolution:
    """A solved level: the cell-DOF displacement ``u`` (P times the conforming solution), the
    nodal reactions and the energy 1/2 u'Ku - F'u of the conforming system."""

    elasticity: QuadElasticity
    u: np.ndarray
    reactions: np.ndarray
    energy: float
    status: str
    reason: str

    @property
    def contact_force(self) -> float:
        return float(self.reactions.sum())


def contact_edges(scene: Scene, elasticity: QuadElasticity):
    """The leaf facets on Gamma_C, their end points a, b (2, n) and outer normals of length
    |b - a| (2, n)."""
    mesh = elasticity.basis.mesh
    facets = boundary_facets_of(scene.is_contact, mesh, elasticity.boundary)
    a, b = mesh.p[:, mesh.facets[0, facets]], mesh.p[:, mesh.facets[1, facets]]
    normal = np.array([(b - a)[1], -(b - a)[0]])
    inward = mesh.p[:, mesh.t[:, mesh.f2t[0, facets]]].mean(axis=1) - a
    normal *= np.where((normal * inward).sum(axis=0) > 0, -1.0, 1.0)
    return facets, a, b, normal


def contact_rows(scene: Scene, elasticity: QuadElasticity) -> tuple[sparse.csr_matrix,
                                                                      np.ndarray]:
    """B (one row per contact node, over the cell DOFs) and the gap at the nodes. A node's
    normal is the length-weighted mean of its facets' outer normals."""
    basis, mesh = elasticity.basis, elasticity.basis.mesh
    facets, a, b, normal = contact_edges(scene, elasticity)
    vertices, rows = np.unique(mesh.facets[:, facets], return_inverse=True)
    vertex_normal = np.array([np.bincount(rows.ravel(), np.tile(c, 2), vertices.size)
                              for c in normal])
    node_dofs = [basis.nodal_dofs[:, vertices]]
    normals, points = [vertex_normal], [mesh.p[:, vertices]]
    if basis.facet_dofs.size:  # Q2: the edge midpoints
        node_dofs.append(basis.facet_dofs[:, facets])
        normals.append(normal)
        points.append(0.5 * (a + b))
    dofs, normals = np.concatenate(node_dofs, axis=1), np.concatenate(normals, axis=1)
    normals /= np.linalg.norm(normals, axis=0)
    m = dofs.shape[1]
    B = sparse.csr_matrix((normals.ravel(), (np.tile(np.arange(m), 2), dofs.ravel())),
                          shape=(m, basis.N))
    gap = np.asarray(scene.gap(np.concatenate(points, axis=1)), dtype=float)
    return B, gap


def solve_quad_vi(scene: Scene, hierarchy: QuadHierarchy, order: int = 1,
                  solver: str = FAST_SOLVER, **options) -> QuadContactSolution:
    """The Q_order VI on the leaves of ``hierarchy`` with a registered QP solver (the fast
    active-set one by default; ``reference`` is Clarabel)."""
    elasticity = assemble_quad_elasticity(scene, hierarchy, order)
    B, gap = contact_rows(scene, elasticity)
    free = elasticity.free
    qp = ContactQP(K=elasticity.K[free][:, free].tocsr(), F=elasticity.F[free],
                   B=(B @ elasticity.P)[:, free].tocsr(), G=gap, row_scale=np.ones(gap.size),
                   objective_scale=float(scene.material.young_modulus))
    answer = SOLVERS.get(solver)(qp, **options)
    if answer.u is None or answer.multipliers is None or not np.all(np.isfinite(answer.u)):
        return QuadContactSolution(elasticity, np.full(elasticity.basis.N, np.nan),
                                   np.full(gap.size, np.nan), float("nan"), "failed",
                                   f"{answer.status}: {answer.reason or 'no solution'}")
    u_free = answer.u
    energy = float(0.5 * u_free @ (qp.K @ u_free) - qp.F @ u_free)
    return QuadContactSolution(elasticity, elasticity.expand(u_free),
                               np.maximum(answer.multipliers, 0.0), energy, answer.status,
                               answer.reason)

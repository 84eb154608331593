"""The primal variational inequality ``vi`` on a quadrilateral hierarchy (Q1, Q2): nodal
constraints u_h(x_i) . n_i <= g(x_i) at every Lagrange node of Gamma_C (its vertices, and for
Q2 its edge midpoints), posed on the conforming space of the quadrilateral family's
``formulations.elasticity.Elasticity`` (docs/theory.md, sections 3 and 15).

Nodes on Gamma_C are never hanging (an edge on the boundary has one cell), so each row is
n_i' at the node's two cell DOFs, taken to the conforming space by P. The multiplier of row i
is the nodal contact reaction, as in ``formulations.vi``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import sparse

from formulations.base import ContactQP
from formulations.contact import outer_normals
from formulations.elasticity import Elasticity, assemble_elasticity
from formulations.solvers.registry import FAST_SOLVER, SOLVERS
from scenes import Scene
from scenes.quad_hierarchy import QuadHierarchy

SIMPSON = np.array([1 / 6, 2 / 3, 1 / 6])  # int of the Q2 trace's nodal functions / |edge|


@dataclass(frozen=True, eq=False)
class ContactEdges:
    """The leaf edges on Gamma_C: ``facets`` of the leaf mesh, end points ``a``, ``b``
    (2, n), outer unit ``normal`` (2, n), ``length`` (n,) and the leaf ``cells`` (n,) (their
    positions in the leaf mesh)."""

    facets: np.ndarray
    a: np.ndarray
    b: np.ndarray
    normal: np.ndarray
    length: np.ndarray
    cells: np.ndarray

    def points(self, t: np.ndarray) -> np.ndarray:
        """Points (2, n, len(t)) at local coordinates t along each edge."""
        return self.a[:, :, None] + (self.b - self.a)[:, :, None] * np.asarray(t)


@dataclass(frozen=True, eq=False)
class QuadContactSolution:
    """A solved level: the cell-DOF displacement ``u`` (P times the conforming solution), the
    reactions (nodal forces for vi, forces on the coarse edges for mixed), the energy
    1/2 u'Ku - F'u of the conforming system, and lambda_h on Gamma_C as its values
    ``edge_pressure`` (n_edges, k + 1) at k + 1 equispaced points of each edge, linear between
    them."""

    elasticity: Elasticity
    u: np.ndarray
    reactions: np.ndarray
    energy: float
    status: str
    reason: str
    edges: ContactEdges
    edge_pressure: np.ndarray

    @property
    def contact_force(self) -> float:
        return float(self.reactions.sum())

    def pressure(self, t: np.ndarray) -> np.ndarray:
        """lambda_h (n_edges, len(t)) at local coordinates t of the contact edges."""
        pieces = self.edge_pressure.shape[1] - 1
        x = np.clip(np.asarray(t, dtype=float), 0.0, 1.0) * pieces
        k = np.minimum(np.floor(x).astype(int), max(pieces - 1, 0))
        values = self.edge_pressure
        if pieces == 0:
            return np.repeat(values, x.size, axis=1)
        return values[:, k] + (values[:, k + 1] - values[:, k]) * (x - k)[None, :]


def contact_edges(scene: Scene, elasticity: Elasticity) -> ContactEdges:
    """The leaf edges on Gamma_C with their outer normals (from each edge's cell)."""
    mesh = elasticity.basis.mesh
    facets = scene.contact_facets(mesh)
    v0, v1 = mesh.facets[:, facets]
    cells = mesh.f2t[0, facets]
    length, normal = outer_normals(mesh, v0, v1, cells)  # as on triangles
    return ContactEdges(facets, mesh.p[:, v0], mesh.p[:, v1], normal, length, cells)


def failed(elasticity: Elasticity, edges: ContactEdges, rows: int, answer,
           nodes: int) -> QuadContactSolution:
    """A solution that failed: NaN arrays, the solver's status and reason."""
    return QuadContactSolution(elasticity, np.full(elasticity.basis.N, np.nan),
                               np.full(rows, np.nan), float("nan"), "failed",
                               f"{answer.status}: {answer.reason or 'no solution'}", edges,
                               np.full((edges.facets.size, nodes), np.nan))


def contact_rows(scene: Scene, elasticity: Elasticity, edges: ContactEdges):
    """B (one row per contact node, over the cell DOFs), the gap at the nodes, the lumped
    boundary mass of each node and the node of each edge's k + 1 points (n_edges, k + 1).
    A vertex's normal is the length-weighted mean of its edges' outer normals."""
    basis, mesh = elasticity.basis, elasticity.basis.mesh
    ends = mesh.facets[:, edges.facets]
    vertices, rows = np.unique(ends, return_inverse=True)
    rows = rows.reshape(ends.shape)
    lumped = np.full(2, 0.5) if basis.facet_dofs.size == 0 else SIMPSON[[0, 2]]
    weight = np.bincount(rows.ravel(), (lumped[:, None] * edges.length).ravel(), vertices.size)
    vertex_normal = np.array([np.bincount(rows.ravel(), np.tile(c * edges.length, 2),
                                          vertices.size) for c in edges.normal])
    node_dofs, normals = [basis.nodal_dofs[:, vertices]], [vertex_normal]
    points, weights = [mesh.p[:, vertices]], [weight]
    edge_nodes = [rows[0], rows[1]]
    if basis.facet_dofs.size:  # Q2: the edge midpoints
        node_dofs.append(basis.facet_dofs[:, edges.facets])
        normals.append(edges.normal)
        points.append(edges.points(np.array([0.5]))[:, :, 0])
        weights.append(SIMPSON[1] * edges.length)
        edge_nodes.insert(1, vertices.size + np.arange(edges.facets.size))
    dofs, normals = np.concatenate(node_dofs, axis=1), np.concatenate(normals, axis=1)
    normals /= np.linalg.norm(normals, axis=0)
    m = dofs.shape[1]
    B = sparse.csr_matrix((normals.ravel(), (np.tile(np.arange(m), 2), dofs.ravel())),
                          shape=(m, basis.N))
    gap = np.asarray(scene.gap(np.concatenate(points, axis=1)), dtype=float)
    return B, gap, np.concatenate(weights), np.array(edge_nodes).T


def solve_quad_vi(scene: Scene, hierarchy: QuadHierarchy, order: int = 1,
                  solver: str = FAST_SOLVER, **options) -> QuadContactSolution:
    """The Q_order VI on the leaves of ``hierarchy`` with a registered QP solver (the fast
    active-set one by default; ``reference`` is Clarabel)."""
    elasticity = assemble_elasticity(scene, hierarchy.mesh(), order)
    edges = contact_edges(scene, elasticity)
    B, gap, weight, edge_nodes = contact_rows(scene, elasticity, edges)
    qp = ContactQP(K=elasticity.K_free, F=elasticity.F_free, B=elasticity.restrict(B), G=gap,
                   row_scale=np.ones(gap.size),
                   objective_scale=float(scene.material.young_modulus),
                   near_null=elasticity.rigid_modes)
    answer = SOLVERS.get(solver)(qp, **options)
    if answer.u is None or answer.multipliers is None or not np.all(np.isfinite(answer.u)):
        return failed(elasticity, edges, gap.size, answer, order + 1)
    u_free = answer.u
    energy = float(0.5 * u_free @ (qp.K @ u_free) - qp.F @ u_free)
    reactions = np.maximum(answer.multipliers, 0.0)
    # lambda_h through the lumped boundary mass, as formulations.vi
    return QuadContactSolution(elasticity, elasticity.expand(u_free), reactions, energy,
                               answer.status, answer.reason, edges,
                               (reactions / weight)[edge_nodes])

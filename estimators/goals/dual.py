"""The dual (adjoint) problem of a goal, linearised at the discrete contact set (docs/theory.md,
20.2): find z in V^+ (the displacements of order p + 1 on the same mesh) and a reaction pi on
the contact nodes A_h where lambda_h > 0 such that

    a(v, z) + (pi, v.n)_{A_h} = j(v)   for all v,      z.n = omega   on A_h,

the contact set held like a clamped normal displacement (a bilateral constraint), free
elsewhere. The constraint is imposed at the Lagrange nodes of order p + 1 by turning each
constrained node's DOFs into its (n, t) frame, so z.n = omega becomes a Dirichlet value and
the system stays symmetric positive definite for any back-end.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
from scipy import sparse

from formulations.cells import family_of
from formulations.cells.evaluation import drop_roundoff, evaluate_at
from formulations.contact.boundary import tangent_frame
from formulations.elasticity import Elasticity, assemble_elasticity
from formulations.solvers.backends import factorise

ACTIVE_SHARE = 1e-6  # a node is in A_h where lambda_h exceeds this share of its maximum
# a dual problem whose matrix has more nonzeros than this is solved by the amg back-end when the
# run names none: in 3D its P(p+1) system has ~7 times the primal's unknowns and ~80 nonzeros
# per row; at 1.5e5 unknowns (1.2e7 nonzeros) amg and PARDISO agreed to 1e-11 in the estimate
# (hertz-3d, vi P1), and PARDISO's factor grew past 9 GiB at 5.6e5 (planar P2: 3.3e5 unknowns)
DUAL_DIRECT_MAX_NONZEROS = 12_000_000


@dataclass(frozen=True, eq=False)
class DualSolution:
    """z (every DOF of ``elasticity``'s basis), the constrained nodes' points (d, m), the rows
    v -> v(x_i).n_i over the basis's DOFs, the reactions pi (forces), an element holding each
    node (for local indicators) and the time of the solve."""

    elasticity: Elasticity
    z: np.ndarray
    points: np.ndarray
    normal_rows: sparse.csr_matrix
    reaction: np.ndarray
    elements: np.ndarray
    seconds: float


def node_pressure(solution, nodes, order: int) -> np.ndarray:
    """lambda_h at the trace nodes of ``nodes`` (its largest value over the facets at a node:
    a pressure discontinuous at a node counts as present)."""
    trace = solution.trace
    values = solution.pressure(trace.lagrange_points(order))  # (n_facets, k), facet_rows' order
    out = np.zeros(nodes.weight.size)
    np.maximum.at(out, nodes.facet_rows.ravel(), values.ravel())
    return out


def contact_set(scene, solution, nodes, order: int) -> np.ndarray:
    """A_h at the trace nodes of ``order``: a vertex where lambda_h > 0 (above ACTIVE_SHARE of
    its maximum) or u_h goes through the obstacle; a node inside a facet where its facet's
    vertices all are (a node half-way to a free vertex is not in contact, whatever lambda_h's
    interpolant says there: the nodal methods' pressure is linear across the zone's end)."""
    lam = node_pressure(solution, nodes, order)
    t = solution.trace.lagrange_points(order)
    through = np.zeros(nodes.weight.size, dtype=bool)
    excess = solution.normal_displacement(t) - np.asarray(
        scene.gap(solution.trace.points(t)), dtype=float)
    through[nodes.facet_rows[excess > 0]] = True
    at = ((lam > ACTIVE_SHARE * lam.max(initial=0.0)) & (lam > 0)) | through
    is_vertex = np.arange(nodes.weight.size) < nodes.vertices.size
    rows = nodes.facet_rows
    whole = np.all(at[rows] | ~is_vertex[rows], axis=1)  # every vertex of the facet in A_h
    inner = np.zeros(nodes.weight.size, dtype=bool)
    inner[rows[whole].ravel()] = True
    return np.where(is_vertex, at, inner)


def node_dofs(elasticity: Elasticity, trace, nodes) -> tuple[np.ndarray, np.ndarray]:
    """The unknowns (d, m) of each trace node's components and whether the node has its own
    (False at a clamped or hanging node, which the dual's constraint leaves alone)."""
    d = nodes.points.shape[0]
    columns = np.full((d, nodes.weight.size), -1)
    own = np.ones(nodes.weight.size, dtype=bool)
    for c in range(d):
        axis = np.zeros_like(nodes.points)
        axis[c] = 1.0
        rows = elasticity.restrict(trace.node_rows(elasticity, nodes, axis)).tocsr()
        rows.data[np.abs(rows.data) < 1e-12] = 0.0
        rows.eliminate_zeros()
        single = (np.diff(rows.indptr) == 1)
        single[single] = np.abs(rows.data[rows.indptr[:-1][single]] - 1.0) < 1e-12
        own &= single
        columns[c, single] = rows.indices[rows.indptr[:-1][single]]
    return columns, own


def rotation(n: int, columns: np.ndarray, normal: np.ndarray) -> sparse.csr_matrix:
    """T (n x n): the identity but for each constrained node's block, whose columns are its
    normal and tangents (the node's first unknown carries z.n)."""
    frame = [normal, *tangent_frame(normal)]
    d, m = columns.shape
    rows = np.concatenate([columns[a] for a in range(d) for _ in range(d)])
    cols = np.concatenate([columns[b] for _ in range(d) for b in range(d)])
    vals = np.concatenate([frame[b][a] for a in range(d) for b in range(d)])
    keep = np.ones(n, dtype=bool)
    keep[columns.ravel()] = False
    eye = np.flatnonzero(keep)
    return sparse.csr_matrix((np.concatenate([vals, np.ones(eye.size)]),
                              (np.concatenate([rows, eye]), np.concatenate([cols, eye]))),
                             shape=(n, n))


def solve_dual(scene, solution, quantity, backend: str | None = None) -> DualSolution:
    """The dual problem of ``quantity`` (``estimators.quantities``) at ``solution``'s contact
    set, in the space of order p + 1 on its mesh."""
    start = time.perf_counter()
    elasticity = assemble_elasticity(scene, solution.elasticity.mesh,
                                     solution.elasticity.order + 1)
    trace = solution.trace
    nodes = trace.nodes(elasticity.order)
    columns, own = node_dofs(elasticity, trace, nodes)
    active = own & contact_set(scene, solution, nodes, elasticity.order)
    columns, normal = columns[:, active], nodes.normal[:, active]
    points = nodes.points[:, active]
    omega = (np.asarray(quantity.weight(points), dtype=float) if quantity.weight is not None
             else np.zeros(points.shape[1]))
    z_free, reaction = held_normal(elasticity, columns, normal, omega,
                                   dual_load(elasticity, quantity), backend)
    return DualSolution(elasticity=elasticity, z=elasticity.expand(z_free), points=points,
                        normal_rows=normal_rows(elasticity, trace, nodes)[np.flatnonzero(active)],
                        reaction=reaction, elements=node_elements(trace, nodes)[active],
                        seconds=time.perf_counter() - start)


def normal_rows(elasticity: Elasticity, trace, nodes) -> sparse.csr_matrix:
    """v -> v(x_i) . n_i at the trace nodes x_i of any order, over every DOF of
    ``elasticity``'s basis (of any order)."""
    evaluation = evaluate_at(elasticity.basis, nodes.points, node_elements(trace, nodes))
    return drop_roundoff(evaluation.matrix(nodes.normal))


def node_elements(trace, nodes) -> np.ndarray:
    """An element holding each trace node (that of a facet it lies on)."""
    out = np.empty(nodes.weight.size, dtype=np.int64)
    out[nodes.facet_rows.ravel()] = np.repeat(trace.element, nodes.facet_rows.shape[1])
    return out


def held_normal(elasticity: Elasticity, columns: np.ndarray, normal: np.ndarray,
                omega: np.ndarray, load: np.ndarray, backend: str | None = None
                ) -> tuple[np.ndarray, np.ndarray]:
    """min 1/2 a(z, z) - (load, z) over the unknowns with z.n = omega at the nodes whose
    unknowns are ``columns`` (d, m), normals ``normal``: z on the unknowns and the nodes'
    reactions pi (a(v, z) + sum pi_i v.n_i = (load, v) for all v)."""
    T = rotation(elasticity.ndofs, columns, normal)
    K = (T.T @ elasticity.K_free @ T).tocsr()
    rhs = T.T @ load
    fixed = columns[0]
    zeta = np.zeros(elasticity.ndofs)
    zeta[fixed] = omega
    free = np.ones(elasticity.ndofs, dtype=bool)
    free[fixed] = False
    inner = np.flatnonzero(free)
    system = K[inner][:, inner]
    if backend is None and system.nnz > DUAL_DIRECT_MAX_NONZEROS:
        backend = "amg"
    factor = factorise(system, backend, T[:, inner].T @ elasticity.rigid_modes
                       if backend == "amg" else None)
    zeta[inner] = factor(rhs[inner] - K[inner][:, fixed] @ omega)
    return T @ zeta, rhs[fixed] - K[fixed] @ zeta


def dual_load(elasticity: Elasticity, quantity) -> np.ndarray:
    """j(phi_i) over the unknowns: the quantity's kernel as a body force by the cell family's
    load rule (0 without one)."""
    if quantity.kernel is None:
        return np.zeros(elasticity.ndofs)
    return elasticity.on_unknowns(family_of(elasticity.mesh).body_load(
        quantity.kernel, elasticity.basis, elasticity.order))

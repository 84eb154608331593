"""The constraint nodes of the nodal variational inequality on a 3D contact surface
(docs/theory.md, section 14.1): the Lagrange nodes of P1 or P2 on the contact triangles, their
lumped boundary mass and mean normals, and the rows B_i = n_i' u_h(x_i).

Pressures from reactions: P1 lumps, giving each vertex a third of every facet's area, so that
lambda_i = r_i / (sum of A / 3) >= 0 node by node, and lambda_h is linear on each facet. For P2
no lumping is consistent: the integral of a vertex's basis function over a triangle is 0, so a
smooth pressure has vertex reactions near 0 and any positive lumped weight there (the
sub-triangle lumping A / 12, A / 4) turns them into vertex pressures near 0 -- lambda_h then
oscillates and its error stalls (measured on free-boundary-3d: 1.44e-3 from 1e5 to 2.5e5 DOFs).
So P2 solves the consistent boundary mass system M lambda = r (M_ij = int phi_i phi_j over
Gamma_C), which reproduces any P2 pressure, and keeps lambda only on the contact triangles with
a node whose reaction pushes (above ACTIVE_FRACTION of the largest), clipped at 0: M^-1 is dense,
so the solve leaves small values of either sign at every node of Gamma_C, and positive ones far
outside the contact zone made its measured radius twice the true one (free-boundary-3d: zone end
0.84, 0.88, 0.77 against 0.4 on three uniform levels; 0.70, 0.55, 0.46 with the cut, which
leaves the zone overshooting by up to a triangle as P1's does, and the pressure error as it
was). Cutting node by node instead puts 0 at the vertices inside the zone whose reaction is 0
(a vertex function of a P2 triangle integrates to 0) and makes lambda_h oscillate: 4 x the
pressure error on an adaptive sequence. lambda_h is the P2 interpolant of the kept values,
clipped at 0. The lumped weights still weigh the nodal normals.
"""

from __future__ import annotations

import numpy as np
from scipy import sparse
from scipy.sparse.linalg import spsolve

from formulations.contact import TraceNodes
from formulations.contact_surface import triangle_lagrange, triangle_rule
from formulations.kkt import ACTIVE_FRACTION

# lumped mass per unit facet area, local nodes in scikit-fem's ElementTriP2 order
# (vertices 0, 1, 2; midpoints of edges 01, 12, 02)
LUMPED = {1: np.full(3, 1 / 3), 2: np.array([1, 1, 1, 3, 3, 3]) / 12}


def surface_nodes(mesh, trace, order: int) -> TraceNodes:
    """Vertices of the contact facets, then (P2) the midpoints of their edges."""
    vertices, local = np.unique(trace.vertices, return_inverse=True)
    rows = local.reshape(trace.vertices.shape).T  # (n_facets, 3)
    points = mesh.p[:, vertices]
    edges = np.zeros(0, dtype=int)
    if order == 2:
        facet_edges = mesh.f2e[:, trace.facets]  # (3, n): scikit-fem's edges 01, 12, 02
        edges, local = np.unique(facet_edges, return_inverse=True)
        rows = np.column_stack([rows, vertices.size + local.reshape(facet_edges.shape).T])
        points = np.concatenate([points, mesh.p[:, mesh.edges[:, edges]].mean(axis=1)], axis=1)
    m = points.shape[1]
    mass = LUMPED[order][None, :] * trace.measure[:, None]
    weight = np.bincount(rows.ravel(), mass.ravel(), m)
    normal = np.array([np.bincount(rows.ravel(), (mass * trace.normal[c][:, None]).ravel(), m)
                       for c in range(3)])
    normal /= np.linalg.norm(normal, axis=0)
    return TraceNodes(points=points, normal=normal, weight=weight, facet_rows=rows,
                      vertices=vertices, edges=edges)


def surface_rows(elasticity, nodes: TraceNodes,
                 directions: np.ndarray | None = None) -> sparse.csr_matrix:
    """B_i = n_i' u_h(x_i): at a P1 or P2 Lagrange node the value is the node's own DOFs.
    ``directions`` (3, m) replaces the normals n_i (the tangential rows of friction)."""
    basis = elasticity.basis
    directions = nodes.normal if directions is None else directions
    dofs = basis.nodal_dofs[:, nodes.vertices]
    if nodes.edges.size:
        dofs = np.concatenate([dofs, basis.edge_dofs[:, nodes.edges]], axis=1)
    m = dofs.shape[1]
    rows = sparse.csr_matrix((directions.ravel(), (np.tile(np.arange(m), 3), dofs.ravel())),
                             shape=(m, basis.N))
    # a component a normal does not have is no column of B: on a plane Gamma_C the condensed
    # solvers' Schur set is then one DOF per node, not three (a dense block 9x smaller)
    rows.eliminate_zeros()
    return rows


def nodal_pressures(trace, nodes: TraceNodes, reaction: np.ndarray) -> np.ndarray:
    """lambda at the nodes from the reactions (module docstring): lumped for P1, the consistent
    boundary mass system for P2, kept where a reaction pushes and clipped at 0."""
    if nodes.facet_rows.shape[1] == 3:
        return reaction / nodes.weight
    points, basis = triangle_lagrange(2)
    t, w = triangle_rule(4)  # exact for products of two quadratics
    phi = basis(t)  # (6, nq)
    local = np.einsum("iq,jq,q->ij", phi, phi, w)  # per unit area
    rows = np.repeat(nodes.facet_rows, 6, axis=1).ravel()
    cols = np.tile(nodes.facet_rows, 6).ravel()
    values = (local.ravel()[None, :] * trace.measure[:, None]).ravel()
    m = nodes.weight.size
    mass = sparse.csc_matrix((values, (rows, cols)), shape=(m, m))
    # an interior-point solver leaves reactions of ~1e-9 relative everywhere: not contact
    pushes = reaction > ACTIVE_FRACTION * reaction.max(initial=0.0)
    pressed = pushes[nodes.facet_rows].any(axis=1)  # facets with a node that pushes
    kept = np.zeros(m, dtype=bool)
    kept[nodes.facet_rows[pressed].ravel()] = True
    return np.where(kept, np.maximum(spsolve(mass, reaction), 0.0), 0.0)


def surface_pressure(values: np.ndarray, t: np.ndarray) -> np.ndarray:
    """lambda_h (n_facets, nq) at local coordinates t (2, nq) from its values at the facet's
    nodes (n_facets, 3 or 6): the P1 or P2 Lagrange interpolant on the facet, clipped at 0 (a
    quadratic through non-negative values can dip below 0 between them)."""
    basis = triangle_lagrange(values.shape[1] // 3)[1]
    return np.maximum(values @ basis(np.asarray(t, dtype=float)), 0.0)

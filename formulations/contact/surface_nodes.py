"""The constraint nodes of the nodal variational inequality on a 3D contact surface
(docs/theory.md, section 14.1): the Lagrange nodes of P1 or P2 on the contact triangles, their
lumped boundary mass and mean normals, and the rows B_i = n_i' u_h(x_i).

Pressures from reactions: P1 lumps, giving each vertex a third of every facet's area, so that
lambda_i = r_i / (sum of A / 3) >= 0 node by node, and lambda_h is linear on each facet. For P2
no lumping is consistent: the integral of a vertex's basis function over a triangle is 0, so a
smooth pressure has vertex reactions near 0 and any positive lumped weight there (the
sub-triangle lumping A / 12, A / 4) turns them into vertex pressures near 0 -- lambda_h then
oscillates and its error stalls (measured on free-boundary-3d: 1.44e-3 from 1e5 to 2.5e5 DOFs).
So P2 fits the reactions: lambda_h on the contact triangles with a node whose reaction
pushes (above ACTIVE_FRACTION of the largest) is the quadratic with non-negative Bernstein
coefficients (so lambda_h >= 0 everywhere, no clipping) whose moments int lambda_h phi_i
match the reactions r_i best in the least-squares sense, each row weighted by 1/sqrt of its
lumped mass (``formulations.nonnegative_fit``). Its integral, the contact force, is then the
sum of the reactions up to what no non-negative quadratic matches (docs/theory.md, 14.1).
Before it, the consistent boundary mass system M lambda = r (exact for any P2 pressure, but M^-1
is dense: it left values of either sign at every node, which had to be cut to the pushing
triangles and clipped at 0) gave a contact force 21 % above the reactions' on free-boundary-3d
at 1944 DOFs and a zone 20 % too wide on hertz-3d at 2.8e4 adaptive DOFs. The lumped weights
still weigh the nodal normals.
"""

from __future__ import annotations

import numpy as np
from scipy import sparse

from formulations.contact.boundary import TraceNodes
from formulations.contact.reference_facets import triangle_lagrange, triangle_rule
from formulations.kkt import ACTIVE_FRACTION
from formulations.nonnegative_fit import bounded_least_squares

# lumped mass per unit facet area, local nodes in scikit-fem's ElementTriP2 order
# (vertices 0, 1, 2; midpoints of edges 01, 12, 02)
LUMPED = {1: np.full(3, 1 / 3), 2: np.array([1, 1, 1, 3, 3, 3]) / 12}
EPSILON = 1e-4  # weight of ||lambda_h|| against the moments: picks one of many fits


def _bernstein_moments() -> np.ndarray:
    """int phi_i B_j per unit area (6, 6): phi_i the P2 Lagrange functions, B_j the P2
    Bernstein polynomials (vertex j: l_j^2; edge ab: 2 l_a l_b), in the same node order."""
    t, w = triangle_rule(4)  # exact for the products of two quadratics
    bary = np.array([1 - t[0] - t[1], t[0], t[1]])
    bernstein = np.array([bary[0] ** 2, bary[1] ** 2, bary[2] ** 2, 2 * bary[0] * bary[1],
                          2 * bary[1] * bary[2], 2 * bary[0] * bary[2]])
    return np.einsum("iq,jq,q->ij", triangle_lagrange(2)[1](t), bernstein, w)


BERNSTEIN_MOMENTS = _bernstein_moments()


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
    """lambda at the nodes from the reactions (module docstring): lumped for P1; for P2 the
    quadratic with non-negative Bernstein coefficients whose moments match the reactions."""
    if nodes.facet_rows.shape[1] == 3:
        return reaction / nodes.weight
    # an interior-point solver leaves reactions of ~1e-9 relative everywhere: not contact
    pushes = reaction > ACTIVE_FRACTION * reaction.max(initial=0.0)
    pressed = np.flatnonzero(pushes[nodes.facet_rows].any(axis=1))
    m = nodes.weight.size
    if pressed.size == 0:
        return np.zeros(m)
    rows = nodes.facet_rows[pressed]                        # (n_pressed, 6)
    area = trace.measure[pressed]
    moments = sparse.csr_matrix((
        (BERNSTEIN_MOMENTS.ravel()[None, :] * area[:, None]).ravel(),
        (np.repeat(rows, 6, axis=1).ravel(), np.tile(rows, 6).ravel())), shape=(m, m))
    on = np.unique(rows)  # the unknown coefficients, and the nodes whose moments are matched
    scale = 1 / np.sqrt(nodes.weight[on])
    # ||sum_j x_j B_j||^2 <= sum_j x_j^2 int B_j (Bernstein: a partition of unity, >= 0)
    norm = np.sqrt(np.bincount(rows.ravel(), np.repeat(area / 6, 6), m)[on])
    A = sparse.diags(scale) @ moments[on][:, on]
    x = bounded_least_squares(A, scale * reaction[on], EPSILON * norm)
    if x is None:  # Clarabel failed: the sub-triangle lumping (module docstring), not zero
        return reaction / nodes.weight
    coefficients = np.zeros(m)
    coefficients[on] = x
    return lagrange_values(nodes.facet_rows, coefficients)


def lagrange_values(facet_rows: np.ndarray, coefficients: np.ndarray) -> np.ndarray:
    """The values at the P2 nodes of the quadratic with Bernstein ``coefficients`` (at a vertex
    its own; at the midpoint of edge ab, (b_a + b_b) / 4 + b_ab / 2)."""
    values = coefficients.copy()
    for edge, (a, b) in enumerate(((0, 1), (1, 2), (0, 2))):
        mid = facet_rows[:, 3 + edge]
        values[mid] = (coefficients[facet_rows[:, a]] + coefficients[facet_rows[:, b]]) / 4 \
            + coefficients[mid] / 2
    return values


def surface_pressure(values: np.ndarray, t: np.ndarray) -> np.ndarray:
    """lambda_h (n_facets, nq) at local coordinates t (2, nq) from its values at the facet's
    nodes (n_facets, 3 or 6): the P1 or P2 Lagrange interpolant on the facet, clipped at 0 (a
    quadratic through non-negative values can dip below 0 between them)."""
    basis = triangle_lagrange(values.shape[1] // 3)[1]
    return np.maximum(values @ basis(np.asarray(t, dtype=float)), 0.0)

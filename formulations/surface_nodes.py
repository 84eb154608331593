"""The constraint nodes of the nodal variational inequality on a 3D contact surface
(docs/theory.md, section 14.1): the Lagrange nodes of P1 or P2 on the contact triangles, their
lumped boundary mass and mean normals, and the rows B_i = n_i' u_h(x_i).

Lumping: P1 gives each vertex a third of every facet's area. For P2 the integral of a vertex's
basis function over a triangle is 0, so the facet is lumped through its four sub-triangles
(vertices and edge midpoints), each giving a third of its area to its corners: A / 12 to each
vertex, A / 4 to each edge midpoint -- positive, and exact for a constant pressure. lambda_h is
then the piecewise linear function on those sub-triangles (on the facet itself for P1).
"""

from __future__ import annotations

import numpy as np
from scipy import sparse

from formulations.contact import TraceNodes

# lumped mass per unit facet area, local nodes in scikit-fem's ElementTriP2 order
# (vertices 0, 1, 2; midpoints of edges 01, 12, 02)
LUMPED = {1: np.full(3, 1 / 3), 2: np.array([1, 1, 1, 3, 3, 3]) / 12}
# the four sub-triangles of a P2 facet as local node numbers
SUB_TRIANGLES = np.array([[0, 3, 5], [3, 1, 4], [5, 4, 2], [4, 5, 3]])


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


def surface_rows(elasticity, nodes: TraceNodes) -> sparse.csr_matrix:
    """B_i = n_i' u_h(x_i): at a P1 or P2 Lagrange node the value is the node's own DOFs."""
    basis = elasticity.basis
    dofs = basis.nodal_dofs[:, nodes.vertices]
    if nodes.edges.size:
        dofs = np.concatenate([dofs, basis.edge_dofs[:, nodes.edges]], axis=1)
    m = dofs.shape[1]
    return sparse.csr_matrix((nodes.normal.ravel(), (np.tile(np.arange(m), 3), dofs.ravel())),
                             shape=(m, basis.N))


def surface_pressure(values: np.ndarray, t: np.ndarray) -> np.ndarray:
    """lambda_h (n_facets, nq) at local coordinates t (2, nq) from its values at the facet's
    nodes (n_facets, 3 or 6): linear on the facet (P1) or on its sub-triangles (P2)."""
    t = np.asarray(t, dtype=float)
    if values.shape[1] == 3:
        return (values[:, 0:1] * (1 - t[0] - t[1]) + values[:, 1:2] * t[0]
                + values[:, 2:3] * t[1])
    x, y = 2 * t[0], 2 * t[1]
    # the sub-triangle holding each point, and the point's coordinates in it (x, y doubled)
    which = np.where(x + y <= 1, 0, np.where(x >= 1, 1, np.where(y >= 1, 2, 3)))
    origin = np.array([[0, 1, 0, 1], [0, 0, 1, 1]])[:, which]
    sign = np.where(which == 3, -1.0, 1.0)
    a, b = sign * (x - origin[0]), sign * (y - origin[1])
    corners = SUB_TRIANGLES[which]  # (nq, 3): nodes at local (0, 0), (1, 0), (0, 1)
    pick = np.arange(t.shape[1])
    return (values[:, corners[pick, 0]] * (1 - a - b) + values[:, corners[pick, 1]] * a
            + values[:, corners[pick, 2]] * b)

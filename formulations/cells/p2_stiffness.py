"""The P2 elasticity stiffness matrix, vectorised over elements and written straight into CSR
(docs/theory.md, section 1): the same matrix as scikit-fem's ``asm(linear_elasticity)`` to
round-off, without its generic quadrature machinery and its list of 144 entries per triangle.

The nodes of P2 are the vertices and the edge midpoints (node nv + e, DOF 2 n + c: scikit-fem's
numbering). With the barycentric coordinates l_i and their gradients g_i, the basis gradients
are (4 l_i - 1) g_i at vertex i and 4 (l_j g_i + l_i g_j) at the midpoint of edge (i, j); the
strain products have degree 2, integrated exactly by the edge-midpoint rule (weights A / 3).
The local blocks are those of ``formulations.cells.p1_stiffness.local_block`` at each point.

Two nodes are coupled by every triangle holding both: a vertex with itself (all triangles
around it), two nodes of one edge (the one or two triangles beside it), and the rest (a vertex
with the midpoint of its opposite edge, two midpoints) by one triangle only. So the pattern is
built from the mesh's edges without sorting all element entries, and only the shared couplings
are summed (by ``np.bincount``).
"""

from __future__ import annotations

import numpy as np
from scipy import sparse
from skfem import MeshTri

from formulations.cells.p1_stiffness import (
    barycentric_gradients,
    block_csr,
    local_block,
    node_pattern,
)
from scenes.topology import TRIANGLE_EDGES, ensure_topology

COMPONENTS = ((0, 0), (0, 1), (1, 0), (1, 1))
OPPOSITE = ((0, 1), (1, 2), (2, 0))  # (vertex i, local edge k opposite to it)
MIDPOINT_PAIRS = ((0, 1), (0, 2), (1, 2))  # local edges k < l


def point_gradients(mesh: MeshTri) -> tuple[np.ndarray, np.ndarray]:
    """Gradients of the six P2 functions at the three edge midpoints, shape (3 points, 6 nodes,
    2, nE) (local node 3 + k: the midpoint of TRIANGLE_EDGES[k]), and the areas."""
    g, area = barycentric_gradients(mesh)
    out = np.empty((3, 6, 2, area.size))
    for q, (a, b) in enumerate(TRIANGLE_EDGES):  # point q: the midpoint of edge q
        lam = np.zeros(3)
        lam[[a, b]] = 0.5
        for i in range(3):
            out[q, i] = (4 * lam[i] - 1) * g[i]
        for k, (i, j) in enumerate(TRIANGLE_EDGES):
            out[q, 3 + k] = 4 * (lam[j] * g[i] + lam[i] * g[j])
    return out, area


def local(G, area, i: int, j: int, c: int, d: int, lam: float, mu: float) -> np.ndarray:
    """a(phi_j e_d, phi_i e_c) on every triangle by the edge-midpoint rule."""
    return area / 3 * sum(local_block(G[q], i, j, c, d, lam, mu) for q in range(3))


def shared_entries(mesh: MeshTri, G, area, lam, mu):
    """(rows, cols, blocks (2, 2, n)) of the couplings along edges and at nodes, each pair
    once in one direction (summed over the triangles holding it)."""
    t, t2f, (a, b) = mesh.t, mesh.t2f, mesh.facets
    nv, ne = mesh.p.shape[1], a.size
    forward = [t[i] == a[t2f[k]] for k, (i, _) in enumerate(TRIANGLE_EDGES)]
    shape = (2, 2)
    diagonal, middle = np.zeros(shape + (nv,)), np.zeros(shape + (ne,))
    edge, first, second = (np.zeros(shape + (ne,)) for _ in range(3))
    for c, d in COMPONENTS:
        for i in range(3):
            diagonal[c, d] += np.bincount(t[i], local(G, area, i, i, c, d, lam, mu), nv)
        for k, (i, j) in enumerate(TRIANGLE_EDGES):
            m, f = 3 + k, forward[k]
            middle[c, d] += np.bincount(t2f[k], local(G, area, m, m, c, d, lam, mu), ne)
            ij, ji = local(G, area, i, j, c, d, lam, mu), local(G, area, j, i, c, d, lam, mu)
            edge[c, d] += np.bincount(t2f[k], np.where(f, ij, ji), ne)  # (a, b)
            im, jm = local(G, area, i, m, c, d, lam, mu), local(G, area, j, m, c, d, lam, mu)
            first[c, d] += np.bincount(t2f[k], np.where(f, im, jm), ne)  # (a, midpoint)
            second[c, d] += np.bincount(t2f[k], np.where(f, jm, im), ne)  # (b, midpoint)
    mid = nv + np.arange(ne)
    rows = (np.arange(nv), mid, a, a, b)
    cols = (np.arange(nv), mid, b, mid, mid)
    return rows, cols, (diagonal, middle, edge, first, second)


def own_entries(mesh: MeshTri, G, area, lam, mu):
    """(rows, cols, blocks) of the couplings held by one triangle only: a vertex with the
    midpoint of its opposite edge, and two midpoints."""
    t, t2f, nv = mesh.t, mesh.t2f, mesh.p.shape[1]
    pairs = [(i, 3 + k, t[i], nv + t2f[k]) for i, k in OPPOSITE]
    pairs += [(3 + k, 3 + m, nv + t2f[k], nv + t2f[m]) for k, m in MIDPOINT_PAIRS]
    rows, cols, blocks = [], [], []
    for i, j, row, col in pairs:
        rows.append(row)
        cols.append(col)
        block = np.empty((2, 2, area.size))
        for c, d in COMPONENTS:
            block[c, d] = local(G, area, i, j, c, d, lam, mu)
        blocks.append(block)
    return rows, cols, blocks


def p2_stiffness(mesh: MeshTri, lam: float, mu: float) -> sparse.csr_matrix:
    """K on the DOFs of scikit-fem's ``ElementVector(ElementTriP2)``."""
    ensure_topology(mesh)
    G, area = point_gradients(mesh)
    rows, cols, blocks = shared_entries(mesh, G, area, lam, mu)
    own = own_entries(mesh, G, area, lam, mu)
    rows, cols, blocks = rows + tuple(own[0]), cols + tuple(own[1]), blocks + tuple(own[2])
    # every off-diagonal coupling in both directions, the reverse block the transpose
    mirrored = range(2, len(rows))
    all_rows = np.concatenate(rows + tuple(cols[k] for k in mirrored))
    all_cols = np.concatenate(cols + tuple(rows[k] for k in mirrored))
    all_blocks = np.concatenate(blocks + tuple(blocks[k].transpose(1, 0, 2) for k in mirrored),
                                axis=2)
    indptr, indices, source = node_pattern(mesh.p.shape[1] + mesh.facets.shape[1], all_rows,
                                           all_cols)
    return block_csr(indptr, indices, all_blocks[:, :, source])

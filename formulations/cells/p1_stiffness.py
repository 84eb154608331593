"""The P1 elasticity stiffness matrix in closed form, vectorised over elements
(docs/theory.md, section 1): the same matrix as scikit-fem's generic ``asm(linear_elasticity)``
with the centroid rule, to round-off, without its quadrature machinery.

With the barycentric gradients g_i of a triangle of area A (constant: P1 strains are constant),
u = phi_j e_d and v = phi_i e_c give

    a(u, v) = A (lam (g_i)_c (g_j)_d + mu (delta_cd g_i . g_j + (g_i)_d (g_j)_c)),

from a(u, v) = (lam div u div v + 2 mu eps(u) : eps(v)). A local DOF 2i + c is node i,
component c, the order of scikit-fem's ``ElementVector(ElementTriP1)``.
"""

from __future__ import annotations

import math

import numpy as np
from scipy import sparse
from skfem import MeshTet, MeshTri
from skfem.mapping import MappingAffine

from scenes.topology import TRIANGLE_EDGES, ensure_topology


def barycentric_gradients(mesh: MeshTri | MeshTet) -> tuple[np.ndarray, np.ndarray]:
    """The gradients g (d + 1 vertices, d components, n_elements) and the measures
    (n_elements) of a triangle or tetrahedron mesh, computed once per mesh (assembly,
    estimators and errors all ask; a mesh's arrays are never changed in place, so the
    read-only copies stored on it stay right)."""
    cached = getattr(mesh, "_barycentric_gradients", None)
    if cached is None:
        cached = _barycentric_gradients(mesh)
        for array in cached:
            array.setflags(write=False)
        mesh._barycentric_gradients = cached
    return cached


def _barycentric_gradients(mesh: MeshTri | MeshTet) -> tuple[np.ndarray, np.ndarray]:
    mapping = mesh.mapping()  # scikit-fem's, cached on the mesh: every basis on it uses it
    if isinstance(mapping, MappingAffine) and mapping.tind is None:
        # the rows of the inverse map are the gradients of the reference coordinates 1 .. d;
        # on triangles the same products and quotients as below, so the same numbers to the bit
        d = mesh.dim()
        g = np.empty((d + 1, d, mesh.t.shape[1]))
        g[1:] = mapping.invA
        g[0] = -g[1:].sum(axis=0)
        return g, np.abs(mapping.detA) / math.factorial(d)
    x = mesh.p[:, mesh.t]  # (2, 3, n)
    d1, d2 = x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]
    det = d1[0] * d2[1] - d1[1] * d2[0]
    g = np.empty((3, 2, det.size))
    g[1, 0], g[1, 1] = d2[1] / det, -d2[0] / det
    g[2, 0], g[2, 1] = -d1[1] / det, d1[0] / det
    g[0] = -g[1] - g[2]
    return g, 0.5 * np.abs(det)


def local_block(g: np.ndarray, i: int, j: int, c: int, d: int, lam: float,
                mu: float) -> np.ndarray:
    """a(phi_j e_d, phi_i e_c) / A for every triangle: lam (g_i)_c (g_j)_d + mu (g_i)_d (g_j)_c
    + mu delta_cd g_i . g_j. Swapping (i, c) and (j, d) only commutes the products, so the
    local matrices are exactly symmetric."""
    value = lam * (g[i, c] * g[j, d]) + mu * (g[i, d] * g[j, c])
    if c == d:
        value += mu * (g[i, 0] * g[j, 0] + g[i, 1] * g[j, 1])
    return value


def node_pattern(n_nodes: int, rows: np.ndarray,
                 cols: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The node graph given by its entries (rows, cols), each pair once, in CSR form with
    sorted columns: (indptr, indices, source), ``source`` giving each CSR entry's place in the
    given list."""
    # entry ids as data: one CSR conversion and an in-row sort carry them to their places
    graph = sparse.csr_matrix((np.arange(1.0, rows.size + 1), (rows, cols)),
                              shape=(n_nodes, n_nodes))
    graph.sort_indices()
    return graph.indptr, graph.indices, graph.data.astype(np.int64) - 1


def vertex_pattern(mesh: MeshTri) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The vertex graph of the mesh (every vertex with itself and with the other ends of its
    edges), ``source`` in [diagonal (n_vertices), edges a -> b (n_edges), edges b -> a]."""
    nv, (a, b) = mesh.p.shape[1], ensure_topology(mesh).facets
    return node_pattern(nv, np.concatenate((np.arange(nv), a, b)),
                        np.concatenate((np.arange(nv), b, a)))


def block_values(mesh: MeshTri, lam: float, mu: float) -> np.ndarray:
    """The 2 x 2 vertex blocks of K in ``vertex_pattern``'s source order, shape (2, 2, n):
    each triangle's local blocks summed onto its vertices and its edges, one component at a
    time (no array of all 36 local entries is ever held)."""
    g, area = barycentric_gradients(mesh)
    t, t2f, (a, _) = mesh.t, mesh.t2f, mesh.facets
    nv, ne = mesh.p.shape[1], a.size
    forward = [t[i] == a[t2f[k]] for k, (i, _) in enumerate(TRIANGLE_EDGES)]
    blocks = np.empty((2, 2, nv + 2 * ne))
    for c, d in ((0, 0), (0, 1), (1, 0), (1, 1)):
        blocks[c, d, :nv] = sum(np.bincount(t[i], area * local_block(g, i, i, c, d, lam, mu),
                                            nv) for i in range(3))
        upper = np.zeros(ne)
        for k, (i, j) in enumerate(TRIANGLE_EDGES):
            # K_ab, a < b the edge's first vertex: the local (i, j) block or its transpose
            value = np.where(forward[k], local_block(g, i, j, c, d, lam, mu),
                             local_block(g, j, i, c, d, lam, mu))
            upper += np.bincount(t2f[k], area * value, ne)
        blocks[c, d, nv:nv + ne] = upper
    blocks[:, :, nv + ne:] = blocks[:, :, nv:nv + ne].transpose(1, 0, 2)  # K_ba = K_ab^T
    return blocks


def p1_stiffness(mesh: MeshTri, lam: float, mu: float) -> sparse.csr_matrix:
    """K on the DOFs of scikit-fem's ``ElementVector(ElementTriP1)`` (DOF 2 v + c: vertex v,
    component c), written straight into CSR: the pattern is the vertex graph with each entry
    a 2 x 2 block, so no list of 36 entries per triangle is sorted."""
    indptr, indices, source = vertex_pattern(mesh)
    return block_csr(indptr, indices, block_values(mesh, lam, mu)[:, :, source])


def block_csr(indptr: np.ndarray, indices: np.ndarray, blocks: np.ndarray) -> sparse.csr_matrix:
    """The CSR matrix on DOFs 2 n + c (node n, component c) of a node graph (indptr, indices)
    whose entry k is the 2 x 2 block blocks[:, :, k]."""
    degree = np.diff(indptr)
    row = np.repeat(np.arange(degree.size), degree)
    within = np.arange(indices.size) - indptr[row]  # place of the entry in its node row
    base = 4 * indptr[row] + 2 * within
    data = np.empty(4 * indices.size)
    columns = np.empty(4 * indices.size, dtype=np.int32)
    for c in range(2):  # DOF row 2 n + c holds [2 w, 2 w + 1 for w in the row's nodes]
        for d in range(2):
            place = base + 2 * c * degree[row] + d
            data[place] = blocks[c, d]
            columns[place] = 2 * indices + d
    dof_indptr = np.empty(2 * degree.size + 1, dtype=np.int64)
    dof_indptr[0] = 0
    dof_indptr[1:] = np.cumsum(np.repeat(2 * degree, 2))
    n = 2 * degree.size
    return sparse.csr_matrix((data, columns, dof_indptr), shape=(n, n))

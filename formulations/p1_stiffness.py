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

import numpy as np
from scipy import sparse
from skfem import MeshTri


def barycentric_gradients(mesh: MeshTri) -> tuple[np.ndarray, np.ndarray]:
    """The gradients g (3 vertices, 2 components, n_elements) and the areas (n_elements)."""
    x = mesh.p[:, mesh.t]  # (2, 3, n)
    d1, d2 = x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]
    det = d1[0] * d2[1] - d1[1] * d2[0]
    g = np.empty((3, 2, det.size))
    g[1, 0], g[1, 1] = d2[1] / det, -d2[0] / det
    g[2, 0], g[2, 1] = -d1[1] / det, d1[0] / det
    g[0] = -g[1] - g[2]
    return g, 0.5 * np.abs(det)


def element_stiffness(mesh: MeshTri, lam: float, mu: float) -> np.ndarray:
    """Local 6 x 6 matrices, shape (6, 6, n_elements)."""
    g, area = barycentric_gradients(mesh)
    gx, gy = g[:, 0], g[:, 1]  # (3, n)
    # outer products first, so that each block is exactly symmetric in (i, j)
    xx, yy = gx[:, None] * gx[None], gy[:, None] * gy[None]
    grad_dot = xx + yy  # g_i . g_j
    blocks = np.empty((3, 2, 3, 2, area.size))
    blocks[:, 0, :, 0] = (lam + mu) * xx + mu * grad_dot
    blocks[:, 1, :, 1] = (lam + mu) * yy + mu * grad_dot
    xy = gx[:, None] * gy[None]
    blocks[:, 0, :, 1] = lam * xy + mu * xy.transpose(1, 0, 2)
    blocks[:, 1, :, 0] = blocks[:, 0, :, 1].transpose(1, 0, 2)  # K symmetric to the last bit
    return blocks.reshape(6, 6, -1) * area


def p1_stiffness(mesh: MeshTri, lam: float, mu: float, element_dofs: np.ndarray,
                 n_dofs: int) -> sparse.csr_matrix:
    """K assembled from the local matrices into the global DOFs ``element_dofs`` (6, n)."""
    local = element_stiffness(mesh, lam, mu)
    rows = np.broadcast_to(element_dofs[:, None, :], local.shape).ravel()
    cols = np.broadcast_to(element_dofs[None, :, :], local.shape).ravel()
    return sparse.csr_matrix((local.ravel(), (rows, cols)), shape=(n_dofs, n_dofs))

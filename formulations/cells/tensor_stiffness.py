"""The elasticity stiffness matrix on quadrilaterals and hexahedra, vectorised over cells
(docs/theory.md, sections 1 and 15.4): the local matrices of vector Q_p from the gradients of
the scalar basis at the (p + 1)^d Gauss points of each cell, through the cell's own
(multilinear) map, so the result is scikit-fem's ``asm(linear_elasticity, ...)`` on that rule,
without its form evaluation per pair of basis functions. Cells go in chunks of CHUNK, so the
local matrices of Q2 hexahedra (81 x 81 each) never all sit in memory at once.

With u = phi_l e_e and v = phi_j e_c,
a(u, v) = lam d_c phi_j d_e phi_l + mu (delta_ce grad phi_j . grad phi_l + d_e phi_j d_c phi_l).
"""

from __future__ import annotations

import numpy as np
from scipy import sparse

from formulations.contact.reference_facets import gauss_legendre

CHUNK = 4096  # cells per chunk: 0.2 GiB of Q2 hexahedral local matrices


def tensor_rule(points: int, d: int = 2) -> tuple[np.ndarray, np.ndarray]:
    """The points^d Gauss rule on the unit square or cube: X (d, nq) (the first coordinate
    slowest), weights (nq,)."""
    t, w = gauss_legendre(points)
    grid = np.array(np.meshgrid(*[t] * d, indexing="ij")).reshape(d, -1)
    weights = np.prod(np.array(np.meshgrid(*[w] * d, indexing="ij")).reshape(d, -1), axis=0)
    return grid, weights


def gradient_products(basis, points: int, cells: np.ndarray) -> np.ndarray:
    """A[j, l, a, b, E] = int_E d_a phi_j d_b phi_l of the scalar basis functions on
    ``cells``."""
    d = basis.mesh.p.shape[0]
    X, w = tensor_rule(points, d)
    scalar = basis.elem.elem
    inverse = basis.mapping.invDF(X, tind=cells)  # (d, d, nE, nq): d X_k / d x_i
    weight = np.abs(basis.mapping.detDF(X, tind=cells)) * w  # (nE, nq)
    grads = np.array([np.einsum("kieq,kq->ieq", inverse, scalar.lbasis(X, j)[1])
                      for j in range(scalar.doflocs.shape[0])])  # (nb, d, nE, nq)
    return np.einsum("jaeq,lbeq->jlabe", grads, grads * weight, optimize=True)


def local_matrices(A: np.ndarray, lam: float, mu: float) -> np.ndarray:
    """(d nb, d nb, nE) from the gradient products A (scikit-fem's vector element: local DOF
    d j + c is scalar function j in component c)."""
    nb, d = A.shape[0], A.shape[2]
    trace = sum(A[:, :, k, k] for k in range(d))
    blocks = np.empty((nb, d, nb, d, A.shape[-1]))
    for c in range(d):
        for e in range(d):
            blocks[:, c, :, e] = (lam * A[:, :, c, e] + mu * A[:, :, e, c]
                                  + (mu * trace if c == e else 0.0))
    return blocks.reshape(d * nb, d * nb, -1)


def tensor_stiffness(basis, lam: float, mu: float, order: int) -> sparse.csr_matrix:
    """K of vector Q_order on ``basis``, on the (order + 1)^d Gauss points."""
    dofs, K = basis.element_dofs, None  # (d nb, nE)
    for start in range(0, dofs.shape[1], CHUNK):
        cells = np.arange(start, min(start + CHUNK, dofs.shape[1]))
        local = local_matrices(gradient_products(basis, order + 1, cells), lam, mu)
        rows = np.broadcast_to(dofs[:, None, cells], local.shape).ravel()
        cols = np.broadcast_to(dofs[None, :, cells], local.shape).ravel()
        part = sparse.csr_matrix((local.ravel(), (rows, cols)), shape=(basis.N, basis.N))
        K = part if K is None else K + part
    return K

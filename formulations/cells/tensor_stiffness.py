"""The elasticity stiffness matrix on quadrilaterals, vectorised over cells (docs/theory.md,
sections 1 and 15.4): the local matrices of vector Q_p from the gradients of the scalar basis
at the (p + 1) x (p + 1) Gauss points of each cell, through the cell's own (bilinear) map, so
the result is scikit-fem's ``asm(linear_elasticity, ...)`` on that rule, without its form
evaluation per pair of basis functions.

With u = phi_l e_e and v = phi_j e_c,
a(u, v) = lam d_c phi_j d_e phi_l + mu (delta_ce grad phi_j . grad phi_l + d_e phi_j d_c phi_l).
"""

from __future__ import annotations

import numpy as np
from scipy import sparse

from formulations.contact.reference_facets import gauss_legendre


def tensor_rule(points: int) -> tuple[np.ndarray, np.ndarray]:
    """The points x points Gauss rule on the unit square: X (2, nq), weights (nq,)."""
    t, w = gauss_legendre(points)
    return (np.array([np.repeat(t, points), np.tile(t, points)]),
            np.repeat(w, points) * np.tile(w, points))


def gradient_products(basis, points: int) -> np.ndarray:
    """A[j, l, a, b, E] = int_E d_a phi_j d_b phi_l of the scalar basis functions."""
    X, w = tensor_rule(points)
    scalar = basis.elem.elem
    inverse = basis.mapping.invDF(X)  # (2, 2, nE, nq): d X_k / d x_i
    weight = np.abs(basis.mapping.detDF(X)) * w  # (nE, nq)
    grads = np.array([np.einsum("kieq,kq->ieq", inverse, scalar.lbasis(X, j)[1])
                      for j in range(scalar.doflocs.shape[0])])  # (nb, 2, nE, nq)
    return np.einsum("jaeq,lbeq->jlabe", grads, grads * weight, optimize=True)


def tensor_stiffness(basis, lam: float, mu: float, order: int) -> sparse.csr_matrix:
    """K of vector Q_order on ``basis`` (scikit-fem's vector element: local DOF 2 j + c is
    scalar function j in component c)."""
    A = gradient_products(basis, order + 1)
    nb = A.shape[0]
    trace = A[:, :, 0, 0] + A[:, :, 1, 1]
    blocks = np.empty((nb, 2, nb, 2, A.shape[-1]))
    for c in range(2):
        for e in range(2):
            blocks[:, c, :, e] = (lam * A[:, :, c, e] + mu * A[:, :, e, c]
                                  + (mu * trace if c == e else 0.0))
    local = blocks.reshape(2 * nb, 2 * nb, -1)
    dofs = basis.element_dofs  # (2 nb, nE)
    rows = np.broadcast_to(dofs[:, None, :], local.shape).ravel()
    cols = np.broadcast_to(dofs[None, :, :], local.shape).ravel()
    return sparse.csr_matrix((local.ravel(), (rows, cols)), shape=(basis.N, basis.N))

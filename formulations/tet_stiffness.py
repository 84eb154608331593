"""The elasticity stiffness matrix on affine tetrahedra, vectorised over elements
(docs/theory.md, sections 1 and 14.1): the same matrix as scikit-fem's generic
``asm(linear_elasticity)``, to round-off, without its form machinery.

On an affine element the gradients of the scalar basis functions are the reference gradients
through the element's inverse Jacobian, g_k = A^-T grad phi_k, and u = phi_l e_d, v = phi_k e_c
give

    a(u, v) = sum_q w_q |det A| (lam (g_k)_c (g_l)_d + mu (delta_cd g_k . g_l + (g_k)_d (g_l)_c)),

exact with a rule of degree 2 (p - 1). A local DOF 3 k + c is node k, component c, the order of
scikit-fem's ``ElementVector``. The local matrices are summed into CSR by scipy's COO
conversion.
"""

from __future__ import annotations

import numpy as np
from scipy import sparse
from skfem import Basis
from skfem.quadrature import get_quadrature
from skfem.refdom import RefTet


def tet_stiffness(basis: Basis, lam: float, mu: float) -> sparse.csr_matrix:
    """K of the vector Lagrange ``basis`` on a tetrahedral mesh (module docstring)."""
    scalar = basis.elem.elem
    order = scalar.maxdeg
    X, W = get_quadrature(RefTet, max(2 * (order - 1), 0))
    mapping = basis.mapping
    inverse = mapping.invA  # (3, 3, nE)
    volume = np.abs(mapping.detA)  # (nE,)
    nb = basis.Nbfun // 3
    reference = np.array([scalar.lbasis(X, k)[1] for k in range(nb)])  # (nb, 3, nq)
    n_elements = inverse.shape[2]
    local = np.zeros((nb, 3, nb, 3, n_elements))
    eye = np.eye(3)
    for q in range(X.shape[1]):
        g = np.einsum("rde,kr->kde", inverse, reference[:, :, q])  # (nb, 3, nE)
        weight = W[q] * volume
        dot = np.einsum("kde,lde->kle", g, g) * weight
        outer = np.einsum("kce,lde->kclde", g, g) * weight
        local += (lam * outer + mu * np.swapaxes(outer, 1, 3)
                  + mu * eye[None, :, None, :, None] * dot[:, None, :, None, :])
    n = 3 * nb
    dofs = basis.element_dofs.astype(np.int32)  # (3 nb, nE), local DOF 3 k + c
    rows = np.broadcast_to(dofs[:, None, :], (n, n, n_elements))
    cols = np.broadcast_to(dofs[None, :, :], (n, n, n_elements))
    K = sparse.coo_matrix((local.reshape(n, n, n_elements).ravel(),
                           (rows.ravel(), cols.ravel())), shape=(basis.N, basis.N))
    return K.tocsr()

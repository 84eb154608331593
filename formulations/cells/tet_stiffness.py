"""The elasticity stiffness matrix on affine tetrahedra, vectorised over elements
(docs/theory.md, sections 1 and 14.1): the same matrix as scikit-fem's generic
``asm(linear_elasticity)``, to round-off, without its form machinery.

On an affine element the gradients of the scalar basis functions are the reference gradients
through the element's inverse Jacobian, g_k = A^-T grad phi_k, and u = phi_l e_d, v = phi_k e_c
give

    a(u, v) = sum_q w_q |det A| (lam (g_k)_c (g_l)_d + mu (delta_cd g_k . g_l + (g_k)_d (g_l)_c)),

exact with a rule of degree 2 (p - 1). A local DOF 3 k + c is node k, component c, the order of
scikit-fem's ``ElementVector``. The local matrices are summed into CSR by scipy's COO
conversion, CHUNK elements at a time: the local matrices and their COO indices take about 20
times the memory of K, which at once set the whole level's peak (1.22 GiB at 104 544 P1 DOFs,
for a K of 55 MB).
"""

from __future__ import annotations

import numpy as np
from scipy import sparse
from skfem import Basis
from skfem.quadrature import get_quadrature
from skfem.refdom import RefTet

CHUNK = 50_000  # elements per chunk (module docstring)


def tet_stiffness(basis: Basis, lam: float, mu: float) -> sparse.csr_matrix:
    """K of the vector Lagrange ``basis`` on a tetrahedral mesh (module docstring), summed
    over chunks of CHUNK elements."""
    scalar = basis.elem.elem
    X, W = get_quadrature(RefTet, max(2 * (scalar.maxdeg - 1), 0))
    nb = basis.Nbfun // 3
    reference = np.array([scalar.lbasis(X, k)[1] for k in range(nb)])  # (nb, 3, nq)
    n_elements = basis.element_dofs.shape[1]
    K = sparse.csr_matrix((basis.N, basis.N))
    for start in range(0, n_elements, CHUNK):
        chunk = slice(start, min(start + CHUNK, n_elements))
        K = K + chunk_stiffness(basis, chunk, reference, W, lam, mu)
    return K


def chunk_stiffness(basis: Basis, chunk: slice, reference: np.ndarray, W: np.ndarray,
                    lam: float, mu: float) -> sparse.csr_matrix:
    """The elements ``chunk``'s part of K."""
    nb = reference.shape[0]
    inverse = basis.mapping.invA[:, :, chunk]  # (3, 3, nE)
    volume = np.abs(basis.mapping.detA[chunk])  # (nE,)
    n_elements = inverse.shape[2]
    local = np.zeros((nb, 3, nb, 3, n_elements))
    eye = np.eye(3)
    for q in range(W.size):
        g = np.einsum("rde,kr->kde", inverse, reference[:, :, q])  # (nb, 3, nE)
        weight = W[q] * volume
        dot = np.einsum("kde,lde->kle", g, g) * weight
        outer = np.einsum("kce,lde->kclde", g, g) * weight
        local += (lam * outer + mu * np.swapaxes(outer, 1, 3)
                  + mu * eye[None, :, None, :, None] * dot[:, None, :, None, :])
    n = 3 * nb
    dofs = basis.element_dofs[:, chunk].astype(np.int32)  # (3 nb, nE), local DOF 3 k + c
    rows = np.broadcast_to(dofs[:, None, :], (n, n, n_elements))
    cols = np.broadcast_to(dofs[None, :, :], (n, n, n_elements))
    K = sparse.coo_matrix((local.reshape(n, n, n_elements).ravel(),
                           (rows.ravel(), cols.ravel())), shape=(basis.N, basis.N))
    return K.tocsr()

"""Raviart-Thomas elements RT_k on tetrahedra of any degree k >= 1 for scikit-fem
(docs/theory.md, section 13.2; the triangles' ``estimators.guaranteed.raviart_thomas`` in 3D).

RT_k = P_k^3 + x P~_k (P~_k: homogeneous polynomials of degree k), of dimension
(k + 1)(k + 2)(k + 4) / 2, normal traces P_k on every face and divergence P_k. Degrees of
freedom on the reference tetrahedron: on each face (v0, v1, v2), its vertices in increasing
local order, the flux density nu . phi (nu the outer normal times twice the face's area,
scikit-fem's ``RefTet.normals``) at the (k + 1)(k + 2) / 2 lattice points v0 + (i (v1 - v0) +
j (v2 - v0)) / k, i + j <= k, in the order of i, then j; inside, the moments of phi against
x^a y^b z^c e_d, a + b + c <= k - 1. On a mesh whose tetrahedra list their vertices in
increasing order (``sorted_tetrahedra``; scikit-fem sorts triangles' vertices, not
tetrahedra's), two tetrahedra see a shared face's vertices, and so its points, in the same
order and differ only in the normal's sign, which ``ElementHdiv.orient`` applies. The nodal
basis is computed once by inverting the matrix of these functionals on the monomial basis.
"""

from __future__ import annotations

import numpy as np
from skfem import MeshTet
from skfem.element import ElementHdiv
from skfem.quadrature import get_quadrature
from skfem.refdom import RefTet


def _exponents(k: int) -> list[tuple[int, int, int]]:
    """(a, b, c) with a + b + c <= k, by total degree."""
    return [(a, b, d - a - b) for d in range(k + 1) for a in range(d, -1, -1)
            for b in range(d - a, -1, -1)]


def monomials(k: int, X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The monomial basis of RT_k at X (3, ...): values (n, 3, ...) and divergences (n, ...)."""
    zero = np.zeros_like(X[0])

    def power(e):
        return np.prod([x**p for x, p in zip(X, e, strict=True)], axis=0) if min(e) >= 0 else zero

    values, divs = [], []
    for e in _exponents(k):
        for d in range(3):
            vector = [zero] * 3
            vector[d] = power(e)
            values.append(np.array(vector))
            divs.append(e[d] * power(tuple(p - (i == d) for i, p in enumerate(e))))
    for e in [e for e in _exponents(k) if sum(e) == k]:  # x times degree exactly k
        values.append(np.array([power(tuple(p + (i == d) for i, p in enumerate(e)))
                                for d in range(3)]))
        divs.append((k + 3) * power(e))
    return np.array(values), np.array(divs)


def face_points(k: int) -> list[np.ndarray]:
    """The DOF points (n_face, 3) of each reference face, in the module docstring's order."""
    corners = RefTet.p.T
    lattice = [(i / k, j / k) for i in range(k + 1) for j in range(k + 1 - i)]
    return [np.array([corners[f[0]] + s * (corners[f[1]] - corners[f[0]])
                      + t * (corners[f[2]] - corners[f[0]]) for s, t in lattice])
            for f in RefTet.facets]


def sorted_tetrahedra(mesh: MeshTet) -> MeshTet:
    """``mesh`` with every tetrahedron's vertices in increasing order (the same elements, in
    the same order), which ``ElementTetRTk`` needs."""
    return MeshTet(mesh.p, np.sort(mesh.t, axis=0))


class ElementTetRTk(ElementHdiv):
    """RT_k on tetrahedra (module docstring); ``ElementTetRTk(1)`` has 15 functions
    (scikit-fem's ``ElementTetRT0`` and ``ElementTetRT1`` are the lowest order, with 4)."""

    refdom = RefTet

    def __init__(self, k: int = 1):
        if int(k) != k or k < 1:
            raise ValueError(f"k={k!r} is not an integer >= 1 (the degree of RT_k)")
        self.k = k = int(k)
        self.facet_dofs = (k + 1) * (k + 2) // 2
        self.interior_dofs = k * (k + 1) * (k + 2) // 2
        self.maxdeg = k + 1
        self.dofnames = ["u^n"] * self.facet_dofs + ["NA"] * self.interior_dofs
        points = face_points(k)
        self.doflocs = np.vstack(points + [np.full((self.interior_dofs, 3), 0.25)])
        functionals = []
        for nu, pts in zip(RefTet.normals, points, strict=True):
            values, _ = monomials(k, pts.T)                                # (n, 3, n_face)
            functionals.append(np.einsum("nip,i->pn", values, nu))
        X, W = get_quadrature(RefTet, 2 * k + 1)
        values, _ = monomials(k, X)
        for e in _exponents(k - 1):
            q = np.prod([x**p for x, p in zip(X, e, strict=True)], axis=0)
            for d in range(3):
                functionals.append((values[:, d] * q * W).sum(axis=-1)[None, :])
        self._coefficients = np.linalg.inv(np.vstack(functionals))  # column i: basis i

    def lbasis(self, X, i):
        values, divs = monomials(self.k, X)
        c = self._coefficients[:, i]
        return np.tensordot(c, values, axes=(0, 0)), np.tensordot(c, divs, axes=(0, 0))

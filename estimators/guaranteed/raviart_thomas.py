"""Raviart-Thomas elements RT_k on triangles of any degree k >= 1 for scikit-fem
(docs/theory.md, section 13.2).

RT_k = P_k^2 + x P~_k (P~_k: homogeneous polynomials of degree k), of dimension (k + 1)(k + 3),
normal traces P_k on every facet and divergence P_k. Degrees of freedom on the reference
triangle: on each facet, the flux density nu . phi (nu the outer normal scaled by the facet's
length) at the k + 1 equispaced points from its lower-numbered vertex to its higher one; inside,
the moments of phi against (x^a y^b, 0) and (0, x^a y^b), a + b <= k - 1. scikit-fem sorts the
vertices of every triangle, so two triangles see a shared facet's points in the same order and
differ only in the normal's sign, which ``ElementHdiv.orient`` applies. The nodal basis is
computed once by inverting the matrix of these functionals on the monomial basis.
"""

from __future__ import annotations

import numpy as np
from skfem.element import ElementHdiv
from skfem.quadrature import get_quadrature
from skfem.refdom import RefTri

# the reference facets of scikit-fem's triangle: (start, end, outer normal times length)
_FACETS = (((0.0, 0.0), (1.0, 0.0), (0.0, -1.0)),
           ((1.0, 0.0), (0.0, 1.0), (1.0, 1.0)),
           ((0.0, 0.0), (0.0, 1.0), (-1.0, 0.0)))


def _exponents(k: int) -> list[tuple[int, int]]:
    return [(a, d - a) for d in range(k + 1) for a in range(d, -1, -1)]


def monomials(k: int, X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The monomial basis of RT_k at X (2, ...): values (n, 2, ...) and divergences (n, ...)."""
    x, y = X
    zero = np.zeros_like(x)
    values, divs = [], []

    def power(a, b):
        return x**a * y**b if a >= 0 and b >= 0 else zero

    for a, b in _exponents(k):
        values += [np.array([power(a, b), zero]), np.array([zero, power(a, b)])]
        divs += [a * power(a - 1, b), b * power(a, b - 1)]
    for a, b in _exponents(k)[-(k + 1):]:  # degree exactly k
        values.append(np.array([power(a + 1, b), power(a, b + 1)]))
        divs.append((k + 2) * power(a, b))
    return np.array(values), np.array(divs)


class ElementTriRTk(ElementHdiv):
    """RT_k on triangles (module docstring); ``ElementTriRTk(1)`` spans what scikit-fem's
    ``ElementTriRT2`` spans."""

    refdom = RefTri

    def __init__(self, k: int = 1):
        if int(k) != k or k < 1:
            raise ValueError(f"k={k!r} is not an integer >= 1 (the degree of RT_k)")
        self.k = k = int(k)
        self.facet_dofs = k + 1
        self.interior_dofs = k * (k + 1)
        self.maxdeg = k + 1
        self.dofnames = ["u^n"] * (k + 1) + ["NA"] * (k * (k + 1))
        s = np.linspace(0.0, 1.0, k + 1)
        points = [np.array(start) + np.outer(s, np.subtract(end, start))
                  for start, end, _ in _FACETS]
        self.doflocs = np.vstack(points + [np.full((k * (k + 1), 2), 1.0 / 3.0)])
        functionals = []
        for (_, _, nu), pts in zip(_FACETS, points, strict=True):
            values, _ = monomials(k, pts.T)                      # (n, 2, k + 1)
            functionals.append(np.einsum("nip,i->pn", values, np.array(nu)))
        X, W = get_quadrature(RefTri, 2 * k + 1)
        values, _ = monomials(k, X)
        x, y = X
        for a, b in _exponents(k - 1):
            q = x**a * y**b
            for c in (0, 1):
                functionals.append((values[:, c] * q * W).sum(axis=-1)[None, :])
        self._coefficients = np.linalg.inv(np.vstack(functionals))  # column i: basis i

    def lbasis(self, X, i):
        values, divs = monomials(self.k, X)
        c = self._coefficients[:, i]
        return np.tensordot(c, values, axes=(0, 0)), np.tensordot(c, divs, axes=(0, 0))

"""Discontinuous P3 on tetrahedra, which scikit-fem lacks (docs/theory.md, section 14.5): the
load moments of the patch problems at k = 2 (``estimators.patch_data.load_moments``) integrate
f against psi_a q_l, a cubic, through the body load of discontinuous P3.

The 20 functions are the Lagrange basis at the points i / 3 (i = 0..3 per coordinate, sum at
most 3) of the reference tetrahedron, all of them interior DOFs: nothing is shared between
elements, so their order needs no orientation. Computed once by inverting the Vandermonde
matrix of the monomials x^a y^b z^c, a + b + c <= 3.
"""

from __future__ import annotations

import numpy as np
from skfem.element import ElementH1
from skfem.refdom import RefTet

_EXPONENTS = [(a, b, c) for a in range(4) for b in range(4 - a) for c in range(4 - a - b)]


def _monomials(X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The 20 monomials at X (3, ...) and their gradients (20, 3, ...)."""
    def power(e):
        return np.prod([x**p if p >= 0 else 0.0 * x for x, p in zip(X, e, strict=True)],
                       axis=0)

    values = np.array([power(e) for e in _EXPONENTS])
    grads = np.array([[e[d] * power(tuple(p - (i == d) for i, p in enumerate(e)))
                       for d in range(3)] for e in _EXPONENTS])
    return values, grads


class ElementTetDGP3(ElementH1):
    """P3 on tetrahedra, every DOF interior (module docstring)."""

    interior_dofs = 20
    maxdeg = 3
    dofnames = ["u"] * 20
    doflocs = np.array(_EXPONENTS, dtype=float) / 3.0
    refdom = RefTet

    def __init__(self):
        values, _ = _monomials(self.doflocs.T)          # (monomial, point)
        self._coefficients = np.linalg.inv(values).T    # column i: basis function i

    def lbasis(self, X, i):
        values, grads = _monomials(np.asarray(X))
        c = self._coefficients[:, i]
        return np.tensordot(c, values, axes=(0, 0)), np.tensordot(c, grads, axes=(0, 0))

"""Discontinuous P3 on tetrahedra, which scikit-fem lacks (docs/theory.md, section 14.5): the
load moments of the patch problems at k = 2 (``estimators.guaranteed.patch_data.load_moments``)
integrate f against psi_a q_l, a cubic, through the body load of discontinuous P3.

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
    ones = np.ones_like(X[0])
    powers = [[ones, x, x * x, x * x * x] for x in X]       # powers[d][p] = X_d^p

    def power(e):
        if min(e) < 0:
            return 0.0 * ones
        return powers[0][e[0]] * powers[1][e[1]] * powers[2][e[2]]

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
        self._last = None

    def _monomials_at(self, X: np.ndarray):
        """``_monomials(X)``, kept for the next call: scikit-fem asks for the 20 functions one
        by one at the same points."""
        last = self._last
        if last is None or last[0].shape != X.shape or not np.array_equal(last[0], X):
            last = self._last = (X.copy(), _monomials(X))
        return last[1]

    def lbasis(self, X, i):
        values, grads = self._monomials_at(np.asarray(X))
        c = self._coefficients[:, i]
        return np.tensordot(c, values, axes=(0, 0)), np.tensordot(c, grads, axes=(0, 0))

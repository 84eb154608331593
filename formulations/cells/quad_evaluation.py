"""grad u_h of a Q1 or Q2 field at any points of given cells, and its derivatives, exactly
(docs/theory.md, section 15), on quadrilaterals and hexahedra.

On a parallelogram or parallelepiped the map x = v0 + A xi from the reference square or cube
is affine, so each component of grad u_h is, in xi, a polynomial of degree at most p in each
variable (Q_p with one degree lost in the direction of differentiation). It is stored per cell
by its values at the (p + 1)^d tensor lattice (a Vandermonde solve) and evaluated or
differentiated anywhere.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from skfem import Basis

from formulations.cells.quad_load import affine_maps

# tolerance of the parallelogram check, relative to the cell's size
PARALLELOGRAM_TOLERANCE = 1e-10


def tensor_exponents(degree: int, d: int = 2) -> np.ndarray:
    """Exponents (d, M) of the monomials prod_k xi_k^a_k with every a_k <= degree."""
    return np.array(np.meshgrid(*[np.arange(degree + 1)] * d, indexing="ij")).reshape(d, -1)


def monomial_values(xi: np.ndarray, exponents: np.ndarray, derivative: int | None = None):
    """The monomials (M, n) at reference points xi (d, n), or their derivatives along xi_r."""
    if derivative is None:
        return np.prod(xi[:, None, :] ** exponents[:, :, None], axis=0)
    power = exponents.copy()
    factor = power[derivative].astype(float)
    power[derivative] = np.maximum(power[derivative] - 1, 0)
    return factor[:, None] * monomial_values(xi, power)


def reference_gradients(scalar, exponents: np.ndarray) -> np.ndarray:
    """D[j, r, m]: the coefficient of monomial m (``exponents``) in d phi_j / d xi_r of the
    scalar element's basis functions (exact: sampled at a lattice of the monomials' degree)."""
    degree = int(exponents.max())
    lattice = exponents / max(degree, 1)
    solve = np.linalg.inv(monomial_values(lattice, exponents).T)
    return np.array([solve @ scalar.lbasis(lattice, j)[1].T
                     for j in range(scalar.doflocs.shape[0])]).transpose(0, 2, 1)


def combine(coefficients: np.ndarray, values: np.ndarray) -> np.ndarray:
    """sum_m coefficients[n, m, :] values[m, n] as the gradient (d, d, n)."""
    d = int(round(np.sqrt(coefficients.shape[-1])))
    return np.einsum("nmc,mn->cn", coefficients, values).reshape(d, d, -1)


@dataclass(frozen=True, eq=False)
class QuadGradient:
    """grad u_h per cell: ``coefficients`` (nE, M, d^2) of the monomials ``exponents`` in the
    reference coordinates of each cell (origin v0, ``inverse`` of A), the last axis the
    components du_i/dx_j (i slowest): cell-major, so that gathering the cells of many points
    reads contiguous rows."""

    origin: np.ndarray
    inverse: np.ndarray
    exponents: np.ndarray
    coefficients: np.ndarray

    @classmethod
    def from_solution(cls, basis: Basis, u: np.ndarray, degree: int) -> QuadGradient:
        """The gradient of the cell-DOF vector ``u`` of a vector Q_degree ``basis``: on a
        parallelogram grad u_h = sum_j u_j A^-T grad_xi phi_j, and grad_xi phi_j is one
        polynomial in xi for every cell (its monomial coefficients found once, on the
        reference square), so no basis is evaluated cell by cell."""
        mesh, d = basis.mesh, basis.mesh.p.shape[0]
        origin, A = affine_maps(mesh)  # (d, nE), (d, d, nE)
        corners = mesh.elem.refdom.p  # (d, 2^d): the reference cell's corners
        affine = origin[:, :, None] + np.einsum("ikE,kq->iEq", A, corners)
        size = np.linalg.norm(A, axis=(0, 1))
        if np.any(np.linalg.norm(mesh._mapping().F(corners) - affine, axis=0).max(axis=1)
                  > PARALLELOGRAM_TOLERANCE * size):
            raise ValueError(f"the {mesh.elem.refdom.name.lower()} cells are not all "
                             "parallelograms or parallelepipeds: their gradients are not "
                             "polynomials in x")
        exponents = tensor_exponents(degree, d)
        inverse = np.linalg.inv(A.transpose(2, 0, 1)).transpose(1, 2, 0)  # rows: d xi_r / dx
        D = reference_gradients(basis.elem.elem, exponents)  # (nb, d r, M)
        nodal = u[basis.element_dofs].reshape(D.shape[0], d, -1)  # (nb, component c, nE)
        by_reference = np.einsum("jcE,jrm->Emcr", nodal, D, optimize=True)  # (nE, M, d, d)
        coefficients = np.einsum("Emcr,rkE->Emck", by_reference, inverse, optimize=True)
        return cls(origin, inverse, exponents,
                   np.ascontiguousarray(coefficients.reshape(-1, exponents.shape[1], d * d)))

    def reference(self, x: np.ndarray, cells: np.ndarray) -> np.ndarray:
        return np.einsum("rkn,kn->rn", self.inverse[:, :, cells], x - self.origin[:, cells])

    @property
    def dim(self) -> int:
        return self.origin.shape[0]

    def at(self, x: np.ndarray, cells: np.ndarray) -> np.ndarray:
        """grad u_h (d, d, n) at points x (d, n) of ``cells``."""
        values = monomial_values(self.reference(x, cells), self.exponents)
        return combine(self.coefficients[cells], values)

    def derivatives_at(self, x: np.ndarray, cells: np.ndarray) -> np.ndarray:
        """d/dx_k (grad u_h)_ij (d, d, d, n) at points x of ``cells``."""
        xi = self.reference(x, cells)
        coefficients = self.coefficients[cells]
        by_reference = np.array([combine(coefficients, monomial_values(xi, self.exponents, r))
                                 for r in range(self.dim)])  # (r, d, d, n)
        return np.einsum("rijn,rkn->ijkn", by_reference, self.inverse[:, :, cells])

    def at_reference(self, X: np.ndarray) -> np.ndarray:
        """grad u_h (d, d, nE, nq) at the same reference points X (d, nq) of every cell."""
        d = self.dim
        return np.einsum("Emc,mq->cEq", self.coefficients, monomial_values(X, self.exponents),
                         optimize=True).reshape(d, d, *self.coefficients.shape[:1], X.shape[1])

    def derivatives_at_reference(self, X: np.ndarray) -> np.ndarray:
        """d/dx_k (grad u_h)_ij (d, d, d, nE, nq) at the same reference points X (d, nq) of
        every cell (no gathering: each cell's own coefficients)."""
        d = self.dim
        by_reference = np.array([
            np.einsum("Emc,mq->cEq", self.coefficients, monomial_values(X, self.exponents, r),
                      optimize=True).reshape(d, d, *self.coefficients.shape[:1], X.shape[1])
            for r in range(d)])  # (r, d, d, nE, nq)
        return np.einsum("rijEq,rkE->ijkEq", by_reference, self.inverse, optimize=True)

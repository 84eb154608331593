"""Values and gradients of a finite element field at given points, each point in a known element
(docs/theory.md, section 9). For every Lagrange order alike: the element's own basis functions
(scikit-fem's ``gbasis``) at the points' reference coordinates, so that nothing here assumes that
a field is linear on a facet or constant on an element.

Facet points are found in the element the facet belongs to (``ContactTrace.element``), never by
point location: a point on the boundary is inside its element exactly, and a field continuous
across elements has one value there anyway.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import sparse
from skfem import Basis, ElementH1, ElementVector

from formulations.cells.p1_stiffness import barycentric_gradients

CHUNK = 200_000  # points per block when summing gradients (bounds the temporary arrays)


@dataclass(frozen=True, eq=False)
class PointEvaluation:
    """The basis functions of ``basis`` at points x (2, n), point i in element ``cells[i]``:
    ``values[k]`` (2, n) and ``gradients[k]`` (2, 2, n) of local basis function k."""

    basis: Basis
    cells: np.ndarray
    values: tuple[np.ndarray, ...]
    gradients: tuple[np.ndarray, ...]

    @property
    def size(self) -> int:
        return int(self.cells.size)

    def matrix(self, direction: np.ndarray) -> sparse.csr_matrix:
        """The sparse operator u -> u_h(x_i) . direction_i (rows: points; columns: all DOFs)."""
        vals = np.concatenate([np.einsum("in,in->n", v, direction) for v in self.values])
        rows = np.tile(np.arange(self.size), len(self.values))
        cols = self.basis.element_dofs[:, self.cells].ravel()
        return sparse.csr_matrix((vals, (rows, cols)), shape=(self.size, self.basis.N))

    def normal_stress_matrix(self, normal: np.ndarray, lame: tuple[float, float]
                             ) -> sparse.csr_matrix:
        """The sparse operator u -> sigma_nn(u_h)(x_i) = n_i . sigma(u_h) n_i with
        sigma = lam tr(eps) I + 2 mu eps (docs/theory.md, section 1)."""
        return self.stress_matrix(normal, normal, lame)

    def stress_matrix(self, normal: np.ndarray, direction: np.ndarray,
                      lame: tuple[float, float]) -> sparse.csr_matrix:
        """u -> d_i . sigma(u_h)(x_i) n_i for directions d_i: sigma_nn for d = n, the shear
        sigma_nt for the tangent d = t (docs/theory.md, section 1)."""
        lam, mu = lame
        along = np.einsum("in,in->n", normal, direction)
        vals = np.concatenate([lam * np.trace(g) * along
                               + mu * (np.einsum("in,ijn,jn->n", direction, g, normal)
                                       + np.einsum("in,ijn,jn->n", normal, g, direction))
                               for g in self.gradients])
        rows = np.tile(np.arange(self.size), len(self.gradients))
        cols = self.basis.element_dofs[:, self.cells].ravel()
        return sparse.csr_matrix((vals, (rows, cols)), shape=(self.size, self.basis.N))

    def value(self, u: np.ndarray) -> np.ndarray:
        """u_h at the points, shape (d, n)."""
        dofs = self.basis.element_dofs[:, self.cells]
        return sum(v * u[dofs[k]] for k, v in enumerate(self.values))

    def gradient(self, u: np.ndarray) -> np.ndarray:
        """grad u_h at the points, grad[i, j] = d u_i / d x_j; shape (d, d, n)."""
        dofs = self.basis.element_dofs[:, self.cells]
        return sum(g * u[dofs[k]] for k, g in enumerate(self.gradients))


def evaluate_at(basis: Basis, x: np.ndarray, cells: np.ndarray) -> PointEvaluation:
    """The basis functions of ``basis`` at points ``x`` (d, n) lying in elements ``cells``."""
    X = basis.mapping.invF(x[:, :, None], tind=cells)
    if isinstance(basis.elem, ElementVector) and isinstance(basis.elem.elem, ElementH1):
        values, gradients = _vector_h1_at(basis, X, cells)
        return PointEvaluation(basis=basis, cells=cells, values=values, gradients=gradients)
    fields = [basis.elem.gbasis(basis.mapping, X, k, tind=cells)[0]
              for k in range(basis.Nbfun)]
    return PointEvaluation(basis=basis, cells=cells,
                           values=tuple(np.asarray(f)[..., 0] for f in fields),
                           gradients=tuple(f.grad[..., 0] for f in fields))


def _vector_h1_at(basis: Basis, X: np.ndarray, cells: np.ndarray):
    """What ``gbasis`` gives for vector Lagrange elements, with the inverse Jacobian computed
    once instead of once per basis function (vector function k = d j + c is the scalar
    function j in component c, scikit-fem's order)."""
    inverse = basis.mapping.invDF(X, tind=cells)[..., 0]  # (d, d, n)
    d = inverse.shape[0]
    values, gradients = [], []
    for j in range(basis.Nbfun // d):
        phi, dphi = basis.elem.elem.lbasis(X, j)
        grad = np.einsum("ijn,in->jn", inverse, dphi[..., 0])
        for c in range(d):
            value, gradient = np.zeros((d, cells.size)), np.zeros((d, d, cells.size))
            value[c], gradient[c] = phi[..., 0], grad
            values.append(value)
            gradients.append(gradient)
    return tuple(values), tuple(gradients)


def evaluate_on_trace(basis: Basis, trace, t: np.ndarray) -> PointEvaluation:
    """The basis functions at local coordinates ``t`` ((nq,) on segments, (2, nq) on
    triangles) of every contact facet of ``trace`` (facet f, point q -> point f * nq + q)."""
    t = np.asarray(t, dtype=float)
    nq = t.shape[-1]
    return evaluate_at(basis, trace.points(t).reshape(trace.dim, -1),
                       np.repeat(trace.element, nq))


def drop_roundoff(matrix: sparse.csr_matrix, relative: float = 1e-12) -> sparse.csr_matrix:
    """``matrix`` without its entries below ``relative`` x its largest: the values of basis
    functions that vanish on a facet, evaluated there, are round-off (~1e-17), not coupling."""
    matrix = matrix.tocsr(copy=True)
    matrix.data[np.abs(matrix.data) < relative * np.abs(matrix.data).max(initial=0.0)] = 0.0
    matrix.eliminate_zeros()
    return matrix


def normal_trace_matrix(basis: Basis, trace, t: np.ndarray) -> sparse.csr_matrix:
    """u -> u_h . n at local coordinates ``t`` of every contact facet (row f * nq + q), on
    all DOFs."""
    t = np.asarray(t, dtype=float)
    return evaluate_on_trace(basis, trace, t).matrix(np.repeat(trace.normal, t.shape[-1],
                                                               axis=1))


def gradients_at_reference(basis: Basis, u: np.ndarray, X: np.ndarray) -> np.ndarray:
    """grad u_h at the same reference points X (d, nX) of every element; shape
    (d, d, n_elements, nX), element-major. Vector Lagrange elements on affine meshes: the
    reference gradients of the scalar functions (the same for every element) through each
    element's inverse Jacobian (no basis object at the points); others: scikit-fem's
    interpolation."""
    inverse = getattr(basis.mapping, "invA", None)  # (2, 2, nE) for affine maps
    if inverse is None or not (isinstance(basis.elem, ElementVector)
                               and isinstance(basis.elem.elem, ElementH1)):
        at = Basis(basis.mesh, basis.elem, quadrature=(X, np.ones(X.shape[1])))
        return at.interpolate(u).grad
    d = inverse.shape[0]
    out = np.zeros((d, d, inverse.shape[2], X.shape[1]))
    for j in range(basis.Nbfun // d):
        _, reference = basis.elem.elem.lbasis(X, j)  # (d, nX)
        gradient = np.einsum("rde,rq->deq", inverse, reference)  # of scalar function j
        for c in range(d):  # vector function d j + c: scalar function j in component c
            out[c] += u[basis.element_dofs[d * j + c]][None, :, None] * gradient
    return out


def p1_gradients(basis: Basis, u: np.ndarray) -> np.ndarray:
    """The constant grad u_h (d, d, n_elements) of a vector P1 field: sum_i u_i g_i' with
    the barycentric gradients g_i (scikit-fem's local DOF d i + c: node i, component c)."""
    g, _ = barycentric_gradients(basis.mesh)  # (d + 1, d, nE)
    nodal = u[basis.element_dofs].reshape(*g.shape[:2], -1)
    return np.einsum("ice,ide->cde", nodal, g)


def gradients_at(basis: Basis, u: np.ndarray, x: np.ndarray, cells: np.ndarray) -> np.ndarray:
    """grad u_h at many points (d, n) in elements ``cells``, in blocks of CHUNK points;
    shape (d, d, n)."""
    d = x.shape[0]
    if basis.elem.maxdeg == 1 and isinstance(basis.elem, ElementVector) and d == 2:
        return p1_gradients(basis, u)[:, :, cells]  # constant per triangle
    out = np.empty((d, d, x.shape[1]))
    for start in range(0, x.shape[1], CHUNK):
        block = slice(start, start + CHUNK)
        out[:, :, block] = evaluate_at(basis, x[:, block], cells[block]).gradient(u)
    return out

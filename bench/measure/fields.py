"""Gradients of finite element fields as polynomials per element, and point location, for
errors between solutions on different meshes (docs/theory.md, section 6).

A ``GradientField`` stores, for every element, the coefficients of grad u_h in the monomials of
the element's reference coordinates (degree p - 1 for P_p): evaluating it at any point of the
element, or just outside it, is a gather and a dot product, with no scikit-fem basis to build
per point. A ``Locator`` finds the element containing each point: the element of the nearest
centroid (a k-d tree), then a walk across the edge of the most negative barycentric coordinate,
all points at once. On tetrahedra the locator is ``bench.measure.locator_3d.TetLocator`` and the
polynomials are in three reference coordinates (docs/theory.md, section 14.6).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
from matplotlib.tri import Triangulation
from scipy.spatial import cKDTree
from skfem import Basis, MeshTri

from bench.measure.locator_3d import TetLocator
from bench.measure.walk import element_neighbours, walk
from formulations.cells.evaluation import gradients_at_reference, p1_gradients
from formulations.cells.p1_stiffness import barycentric_gradients
from formulations.elasticity import vector_element

CHUNK = 50_000  # points per block when evaluating: small temporaries are reused, not faulted in
# afresh (measured at 10^6 DOFs against the P3 reference: 0.96-1.14 s against 1.14-1.30 s with
# 250 000)
@dataclass(frozen=True, eq=False)
class Locator:
    """Point location in one triangle mesh (module docstring)."""

    mesh: MeshTri
    origin: np.ndarray  # (2, nE): vertex 0 of every element
    inverse: np.ndarray  # (2, 2, nE): the inverse of the affine map's matrix
    area: np.ndarray

    @classmethod
    def from_mesh(cls, mesh: MeshTri) -> Locator:
        # the rows of the inverse map are the gradients of the reference coordinates xi = the
        # barycentric coordinate of vertex 1, eta = that of vertex 2 (computed once per mesh)
        gradients, area = barycentric_gradients(mesh)
        return cls(mesh, mesh.p[:, mesh.t[0]], gradients[1:], area)

    @functools.cached_property
    def neighbours(self) -> np.ndarray:
        return element_neighbours(self.mesh)

    @functools.cached_property
    def tree(self) -> cKDTree:
        return cKDTree(self.mesh.p[:, self.mesh.t].mean(axis=1).T)

    def reference_coordinates(self, x: np.ndarray, cells: np.ndarray) -> np.ndarray:
        """The coordinates (2, n) of points x (2, n) in the reference triangle of ``cells``
        (outside it for a point outside its cell)."""
        d = x - self.origin[:, cells]
        inv = self.inverse[:, :, cells]
        return np.array([inv[0, 0] * d[0] + inv[0, 1] * d[1], inv[1, 0] * d[0] + inv[1, 1] * d[1]])

    def barycentric(self, x: np.ndarray, cells: np.ndarray) -> np.ndarray:
        xi = self.reference_coordinates(x, cells)
        return np.array([1.0 - xi[0] - xi[1], xi[0], xi[1]])

    def find(self, x: np.ndarray, start: np.ndarray | None = None) -> np.ndarray:
        """The element containing each point of x (2, n), walking from the elements
        ``start`` if given; ValueError for a point outside."""
        return walk(self, x, start)

    def finish(self, x, cells, todo) -> np.ndarray:
        """matplotlib's trapezoid finder for the points the walk left."""
        triangulation = Triangulation(self.mesh.p[0], self.mesh.p[1], self.mesh.t.T)
        found = triangulation.get_trifinder()(x[0, todo], x[1, todo])
        if (found < 0).any():
            bad = todo[np.flatnonzero(found < 0)[0]]
            raise ValueError(f"point ({x[0, bad]}, {x[1, bad]}) lies outside the mesh")
        cells[todo] = found
        return cells


def _exponents(total: int, dim: int) -> list[tuple[int, ...]]:
    """The exponents of ``dim`` variables summing to ``total``, the first ones descending."""
    if dim == 1:
        return [(total,)]
    return [(i, *rest) for i in range(total, -1, -1) for rest in _exponents(total - i, dim - 1)]


def monomials(degree: int, dim: int = 2) -> list[tuple[int, ...]]:
    """Exponents (i, j) of xi^i eta^j with i + j <= degree ((i, j, k) in 3D), by degree."""
    return [e for total in range(degree + 1) for e in _exponents(total, dim)]


def _lattice(degree: int, dim: int = 2) -> np.ndarray:
    """Points (dim, n) of the reference simplex on which the monomials of ``degree`` are
    unisolvent: the centroid for degree 0, the degree-d lattice otherwise."""
    if degree == 0:
        return np.full((dim, 1), 1.0 / (dim + 1))
    return np.array([[e / degree for e in exponents]
                     for exponents in monomials(degree, dim)]).T


def _powers(xi: np.ndarray, degree: int) -> np.ndarray:
    return np.array([np.prod([x**k for x, k in zip(xi, exponents, strict=True)], axis=0)
                     for exponents in monomials(degree, xi.shape[0])])


def locator_for(mesh):
    """The point locator of a triangle or a tetrahedral mesh."""
    return TetLocator.from_mesh(mesh) if mesh.dim() == 3 else Locator.from_mesh(mesh)


@dataclass(frozen=True, eq=False)
class GradientField:
    """grad u_h of a P_p field: per element, the coefficients of a polynomial of degree p - 1
    in the reference coordinates (module docstring)."""

    locator: Locator | TetLocator
    degree: int
    coefficients: np.ndarray  # (d, d, n_monomials, nE)

    @classmethod
    def from_solution(cls, basis: Basis, u: np.ndarray) -> GradientField:
        """The field of the DOF vector ``u`` of a vector P_p ``basis``."""
        degree, dim = basis.elem.maxdeg - 1, basis.mesh.dim()
        if degree == 0:  # P1: the constant gradient of each element
            return cls(locator_for(basis.mesh), 0, p1_gradients(basis, u)[:, :, None, :])
        nodes = _lattice(degree, dim)
        values = gradients_at_reference(basis, u, nodes)  # (d, d, nE, n_nodes)
        solve = np.linalg.inv(_powers(nodes, degree).T)  # Vandermonde: coefficients <- values
        coefficients = np.einsum("mk,ijek->ijme", solve, values)
        return cls(locator_for(basis.mesh), degree, coefficients)

    @classmethod
    def from_dofs(cls, mesh, order: int, u: np.ndarray) -> GradientField:
        return cls.from_solution(Basis(mesh, vector_element(order, mesh.dim()), intorder=1), u)

    @property
    def area(self) -> np.ndarray:
        return self.locator.area

    def at(self, x: np.ndarray, cells: np.ndarray) -> np.ndarray:
        """grad u_h (d, d, n) at points x (d, n) from the polynomials of ``cells`` (extended
        beyond the element for a point outside it)."""
        if self.degree == 0:  # a constant per element (P1): nothing to evaluate
            return self.coefficients[:, :, 0, cells]
        d = x.shape[0]
        out = np.empty((d, d, x.shape[1]))
        for start in range(0, x.shape[1], CHUNK):
            block = slice(start, start + CHUNK)
            [out[:, :, block]] = self.at_each([x[:, block]], cells[block])
        return out

    def at_each(self, points: list[np.ndarray], cells: np.ndarray) -> list[np.ndarray]:
        """``at(x, cells)`` for every x in ``points`` (each (d, n), the same cells): the cells'
        polynomials and maps are gathered once for all of them."""
        if self.degree == 0:
            return [self.coefficients[:, :, 0, cells]] * len(points)
        coefficients = self.coefficients[:, :, :, cells]
        origin, inv = self.locator.origin[:, cells], self.locator.inverse[:, :, cells]
        out = []
        for x in points:
            if x.shape[0] == 3:
                xi = np.einsum("rke,ke->re", inv, x - origin)
                out.append(np.einsum("ijmn,mn->ijn", coefficients, _powers(xi, self.degree)))
                continue
            d = x - origin
            xi = np.array([inv[0, 0] * d[0] + inv[0, 1] * d[1],
                           inv[1, 0] * d[0] + inv[1, 1] * d[1]])
            out.append(np.einsum("ijmn,mn->ijn", coefficients, _powers(xi, self.degree)))
        return out

"""The gradient of a Q1 or Q2 field on a quadrilateral mesh as a ``GradientField`` on triangles,
so that its error against a reference on another mesh is measured by the same
``energy_difference`` as every triangle field (docs/theory.md, section 15).

Each cell is split along its diagonal v0-v2 into two triangles. On a parallelogram the bilinear
map is affine, so the gradient of a Q_p field is, on each half, a polynomial of degree at most
2p - 1 in x (Q1: linear; Q2: cubic): it is sampled at the lattice of that degree on the half
and stored exactly, as ``GradientField.from_solution`` does for P_p (the values from the
cell's own gradient polynomials, ``formulations.cells.quad_evaluation``; cells that are not
parallelograms are refused there).
"""

from __future__ import annotations

import numpy as np
from skfem import Basis, MeshTri

from bench.measure.fields import GradientField, Locator, _lattice, _powers, monomials
from formulations.cells import family_of
from formulations.cells.quad_evaluation import QuadGradient

# the halves of the reference square [0, 1]^2: corners (v0, v1, v2) and (v0, v2, v3)
HALVES = (np.array([[0.0, 1.0, 1.0], [0.0, 0.0, 1.0]]),
          np.array([[0.0, 1.0, 0.0], [0.0, 1.0, 1.0]]))


def quad_gradient_field(basis: Basis, u: np.ndarray) -> GradientField:
    """grad u of the cell-DOF vector ``u`` of a vector Q_p ``basis`` on triangles: triangle
    2k is the half (v0, v1, v2) of cell k, triangle 2k + 1 the half (v0, v2, v3)."""
    mesh = basis.mesh
    degree = 2 * _order(basis) - 1
    nodes = _lattice(degree, 2)  # (2, k) in the reference triangle
    field = QuadGradient.from_solution(basis, u, _order(basis))
    values = []
    for half in HALVES:
        square = half[:, :1] + (half[:, 1:2] - half[:, :1]) * nodes[0] \
            + (half[:, 2:3] - half[:, :1]) * nodes[1]
        values.append(field.at_reference(square))  # (2, 2, nE, k)
    grad = np.stack(values, axis=3).reshape(2, 2, -1, nodes.shape[1])  # cell-major halves
    solve = np.linalg.inv(_powers(nodes, degree).T)
    coefficients = np.einsum("mk,ijek->ijme", solve, grad)
    t = mesh.t
    triangles = np.stack([t[[0, 1, 2]], t[[0, 2, 3]]], axis=2).reshape(3, -1)
    # unsorted: the coefficients are in the reference coordinates of this vertex order
    halves = MeshTri(np.ascontiguousarray(mesh.p), triangles, sort_t=False)
    return GradientField(Locator.from_mesh(halves), degree, coefficients)


def gradient_field_of(basis: Basis, u: np.ndarray) -> GradientField:
    """The ``GradientField`` of a solution on any mesh: split into triangles on tensor-product
    cells (``quad_gradient_field``), the element's own polynomials on simplices."""
    if family_of(basis.mesh).tensor_product:
        return quad_gradient_field(basis, u)
    return GradientField.from_solution(basis, u)


def _order(basis: Basis) -> int:
    """p of a vector Q_p basis (its scalar element's degree in each variable)."""
    return 1 if basis.elem.elem.facet_dofs == 0 else 2


def gradient_derivatives_at(field: GradientField, x: np.ndarray,
                            cells: np.ndarray) -> np.ndarray:
    """d/dx_k of grad u (2, 2, 2, n) at points x (2, n) of the triangles ``cells`` of
    ``field``: its polynomials differentiated exactly, through each triangle's inverse map."""
    xi = field.locator.reference_coordinates(x, cells)
    exponents = monomials(field.degree)
    derivatives = []
    for r in range(2):  # d/dxi_r of every monomial
        rows = []
        for exponent in exponents:
            power = list(exponent)
            factor = power[r]
            power[r] = max(power[r] - 1, 0)
            rows.append(factor * xi[0] ** power[0] * xi[1] ** power[1])
        derivatives.append(np.array(rows))  # (M, n)
    coefficients = field.coefficients[:, :, :, cells]  # (2, 2, M, n)
    inverse = field.locator.inverse[:, :, cells]  # (r, k, n)
    by_reference = np.array([np.einsum("ijmn,mn->ijn", coefficients, d)
                             for d in derivatives])  # (r, 2, 2, n)
    return np.einsum("rijn,rkn->ijkn", by_reference, inverse)

"""Errors of quadrilateral fields against fields on other meshes: the Q_p gradient on the
cells' triangle halves is exact, so the energy norm of the difference to a field of the same
function vanishes, and the error of an interpolant matches the one integrated on the quads."""

import numpy as np
import pytest
from skfem import Basis, ElementQuad1, ElementQuad2, ElementTriP2, ElementVector, MeshTri

from bench.measure.discretisation_error import energy_density
from bench.measure.fields import GradientField
from bench.measure.nonnested import energy_difference
from bench.measure.quad_fields import quad_gradient_field
from scenes.quad_hierarchy import QuadHierarchy

LAME = (1.3, 0.7)


def field(x):
    """A quadratic displacement (in P2 on triangles, not in Q1)."""
    return np.array([x[0] ** 2 - 0.5 * x[0] * x[1] + 0.2 * x[1], x[1] ** 2 + 0.3 * x[0] ** 2])


def gradient(x):
    return np.array([[2 * x[0] - 0.5 * x[1], -0.5 * x[0] + 0.2],
                     [0.6 * x[0], 2 * x[1]]])


def interpolant(basis):
    component = np.zeros(basis.N, dtype=int)
    for dofs in (basis.nodal_dofs, basis.facet_dofs, basis.interior_dofs):
        if dofs.size:
            component[dofs[1]] = 1
    return field(basis.doflocs)[component, np.arange(basis.N)]


@pytest.fixture
def quads():
    hierarchy = QuadHierarchy.from_tensor(np.linspace(-1, 1, 4), np.linspace(0, 1, 3))
    return hierarchy.refined([1]).mesh()


@pytest.fixture
def exact_p2():
    grid = np.linspace(-1, 1, 7)
    mesh = MeshTri.init_tensor(grid, np.linspace(0, 1, 4))
    basis = Basis(mesh, ElementVector(ElementTriP2()))
    return GradientField.from_solution(basis, interpolant(basis))


def test_a_q2_field_of_the_function_has_no_error(quads, exact_p2):
    basis = Basis(quads, ElementVector(ElementQuad2()))
    u = interpolant(basis)  # the quadratic is in Q2: its interpolant is the function
    # round-off of evaluating cubic polynomials: 1e-12 of the field's energy norm (about 2)
    assert energy_difference(quad_gradient_field(basis, u), exact_p2, LAME) < 1e-10


def test_the_error_of_a_q1_interpolant_is_the_one_integrated_on_the_quads(quads, exact_p2):
    basis = Basis(quads, ElementVector(ElementQuad1()), intorder=6)
    u = interpolant(basis)
    measured = energy_difference(quad_gradient_field(basis, u), exact_p2, LAME)

    grad_h = basis.interpolate(u).grad  # (2, 2, nE, nq)
    error = grad_h - gradient(basis.global_coordinates())
    integrated = float((energy_density(error, *LAME) * basis.dx).sum())
    assert measured > 0.05  # a real error, not round-off
    # the same integral two ways: both rules are exact for these polynomials
    assert measured == pytest.approx(np.sqrt(integrated), rel=1e-12)

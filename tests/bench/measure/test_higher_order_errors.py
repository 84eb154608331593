"""Energy errors of P2 and P3 solutions: against an exact solution and against a P1 field on a
finer nested mesh, checked with fields whose gradients are known analytically."""

import dataclasses

import numpy as np
import pytest
from skfem import Basis, ElementTriP1

from bench.measure.discretisation_error import energy_density, exact_errors
from bench.measure.fields import GradientField
from bench.measure.nonnested import energy_difference
from formulations import get_formulation, solve
from scenes import get_scene

FIELDS = {  # degree-p polynomial displacements and their gradients
    2: (lambda x: np.array([x[0] ** 2 - 0.4 * x[0] * x[1], 0.7 * x[1] ** 2 + x[0]]),
        lambda x: np.array([[2 * x[0] - 0.4 * x[1], -0.4 * x[0]],
                            [1 + 0 * x[0], 1.4 * x[1]]])),
    3: (lambda x: np.array([x[0] ** 2 * x[1] - 0.3 * x[1] ** 3, 0.5 * x[0] ** 3 - x[0] * x[1]]),
        lambda x: np.array([[2 * x[0] * x[1], x[0] ** 2 - 0.9 * x[1] ** 2],
                            [1.5 * x[0] ** 2 - x[1], -x[0]]])),
}


def polynomial_solution(order):
    """A P_order solution of free-boundary whose u_h is replaced by a degree-p polynomial."""
    scene = get_scene("free-boundary")
    sol = solve(get_formulation("mixed")(scene, scene.mesh.refined(1), order=order),
                "active-set")
    basis = sol.elasticity.basis
    u = np.zeros(basis.N)
    values = FIELDS[order][0](basis.doflocs)
    for c, dofs in enumerate(basis.split_indices()):
        u[dofs] = values[c][dofs]
    return dataclasses.replace(sol, u=u)


@pytest.mark.parametrize("order", (2, 3))
def test_error_against_a_nested_p1_field_is_exact(order):
    # the P1 field is the nodal interpolant of sin-like data on the mesh refined twice; the
    # independent value integrates grad(field) - grad(polynomial) with a rule of order 8
    sol = polynomial_solution(order)
    fine = sol.elasticity.mesh.refined(2)
    u_nodal = np.array([np.sin(fine.p[0]) * fine.p[1], np.cos(fine.p[1]) + fine.p[0] ** 2])
    p1 = Basis(fine, sol.elasticity.basis.elem.__class__(ElementTriP1()))
    u = np.zeros(p1.N)
    u[p1.nodal_dofs] = u_nodal
    field = GradientField.from_solution(p1, u)
    basis = Basis(fine, ElementTriP1(), intorder=8)
    grad_field = np.array([basis.interpolate(u_nodal[c]).grad for c in (0, 1)])
    x = np.asarray(basis.global_coordinates())
    difference = grad_field - FIELDS[order][1](x)
    expected = np.sqrt((energy_density(difference, *sol.elasticity.lame) * basis.dx).sum())
    judged = GradientField.from_solution(sol.elasticity.basis, sol.u)
    lame = sol.elasticity.lame
    # either mesh first: the coarse one's cells are split into the fine elements, or the fine
    # elements lie in one coarse element each
    assert energy_difference(judged, field, lame) == pytest.approx(expected, rel=1e-10)
    assert energy_difference(field, judged, lame) == pytest.approx(expected, rel=1e-10)


@pytest.mark.parametrize("order", (2, 3))
def test_exact_error_matches_an_independent_integral(order):
    # the scene's exact u against u_h = a polynomial: the rule of degree 6 + 2(p - 1) matches
    # an independent order-10 rule on the mesh refined twice
    sol = polynomial_solution(order)
    scene = get_scene("free-boundary")
    measured = exact_errors(scene, sol).energy_error
    basis = Basis(sol.elasticity.mesh.refined(2), ElementTriP1(), intorder=10)
    x = np.asarray(basis.global_coordinates())
    difference = scene.exact.gradient(x) - FIELDS[order][1](x)
    expected = np.sqrt((energy_density(difference, *sol.elasticity.lame) * basis.dx).sum())
    assert measured == pytest.approx(expected, rel=1e-6)

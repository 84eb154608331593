"""Estimators for P2 and P3: the parts that change with the order, checked on polynomial
fields whose answers are known analytically."""

import dataclasses

import numpy as np
import pytest
from skfem import Basis

from estimators.averaging import averaging_indicators
from estimators.residual.triangles import interior_jumps, stress_divergence
from formulations import get_formulation, solve
from formulations.elasticity import ELEMENTS
from scenes import get_scene


def polynomial_solution(order, field):
    """A solved P_order discretisation of the free-boundary scene with u_h replaced by the
    interpolant of the polynomial ``field`` (degree <= p: the interpolant is the field)."""
    scene = get_scene("free-boundary")
    sol = solve(get_formulation("mixed")(scene, scene.mesh.refined(1), order=order),
                "active-set")
    basis = sol.elasticity.basis
    u = np.zeros(basis.N)
    values = field(basis.doflocs)
    for c, dofs in enumerate(basis.split_indices()):
        u[dofs] = values[c][dofs]
    return dataclasses.replace(sol, u=u)


FIELDS = {
    2: lambda x: np.array([x[0] ** 2 - 0.4 * x[0] * x[1], 0.7 * x[1] ** 2 + x[0]]),
    3: lambda x: np.array([x[0] ** 2 * x[1] - 0.3 * x[1] ** 3, 0.5 * x[0] ** 3 - x[0] * x[1]]),
}
# div sigma(u) = (lam + mu) grad div u + mu laplace u, by hand for the fields above
DIV_GRAD = {  # (grad div u, laplace u) as functions of x
    2: (lambda x: np.array([2 + 0 * x[0], 1 + 0 * x[0]]),  # div u = 2x + y
        lambda x: np.array([2 + 0 * x[0], 1.4 + 0 * x[0]])),
    3: (lambda x: np.array([2 * x[1] - 1, 2 * x[0]]),  # div u = 2xy - x
        lambda x: np.array([0.2 * x[1], 3 * x[0]])),
}


@pytest.mark.parametrize("order", (2, 3))
def test_stress_divergence_is_exact_for_polynomial_fields(order):
    sol = polynomial_solution(order, FIELDS[order])
    lam, mu = sol.elasticity.lame
    basis = Basis(sol.elasticity.mesh, sol.elasticity.basis.elem, intorder=4)
    x = np.asarray(basis.global_coordinates())
    grad_div, laplace = DIV_GRAD[order]
    expected = (lam + mu) * grad_div(x) + mu * laplace(x)
    assert np.abs(stress_divergence(sol, basis) - expected).max() < 1e-9 * np.abs(
        expected).max()


@pytest.mark.parametrize("order", (2, 3))
def test_smooth_fields_have_no_jumps_and_nothing_to_average(order):
    # sigma(u) is continuous for a global polynomial u: the interior jumps vanish, and the
    # recovery into continuous P_p reproduces sigma_h (degree p - 1) exactly
    sol = polynomial_solution(order, FIELDS[order])
    scale = np.abs(sol.u).max() ** 2
    assert interior_jumps(sol).max() < 1e-20 * max(scale, 1.0)
    assert averaging_indicators(sol).max() < 1e-20 * max(scale, 1.0)


@pytest.mark.parametrize("order", (2, 3))
def test_a_field_of_degree_above_p_is_seen_by_both(order):
    # a degree p + 1 field interpolated in P_p has jumps and a stress the recovery cannot
    # reproduce: both estimators are positive
    sol = polynomial_solution(order, lambda x: np.array([x[0] ** (order + 1), x[1] ** (order + 1)
                                                         + x[0] * x[1] ** order]))
    assert interior_jumps(sol).sum() > 0 and averaging_indicators(sol).sum() > 0
    assert ELEMENTS[order]  # the order under test is a registered element

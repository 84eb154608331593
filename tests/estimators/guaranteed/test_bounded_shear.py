"""The bounded auxiliary shear traction of the guaranteed bound under Tresca friction
(docs/theory.md, 17.5)."""

import numpy as np
import pytest

from estimators.guaranteed.bounded_shear import bounded_shear, coefficient_bounds
from estimators.guaranteed.equilibrated import equilibrate
from estimators.guaranteed.guaranteed_contact import QUADRATURE, traction_balance
from estimators.guaranteed.guaranteed_friction import (
    balanced_shear,
    raw_shear,
    shear_excess,
    vertex_tangents,
)
from estimators.guaranteed.nonnegative_traction import bernstein_polynomial
from formulations import get_formulation, solve
from formulations.contact.reference_facets import gauss_legendre
from formulations.friction.slack import contact_tangent
from scenes import get_scene


@pytest.fixture(scope="module")
def stick_slip_mixed():
    scene = get_scene("stick-slip")
    solution = solve(get_formulation("mixed")(scene, scene.mesh.refined(3)), "active-set")
    _, interior, _, _, _, clamped, shear = equilibrate(scene, solution)
    return scene, solution, interior, clamped, shear


def tangential(trace, moments, clamped):
    on = np.unique(np.concatenate(trace.vertices))
    on = on[~clamped[on]]
    return (moments[on] * vertex_tangents(trace)[:, on].T).sum(axis=1)


def excess_norm(scene, solution, shear) -> float:
    t, w = gauss_legendre(QUADRATURE)
    excess = shear_excess(scene, solution, shear, t)[2]
    return float(np.sqrt(solution.trace.integrate(excess**2, w).sum()))


def test_moments_that_a_bounded_shear_has_are_met_within_the_bound(stick_slip_mixed):
    """Moments of a shear with Bernstein coefficients at half the slip bound: the box least
    squares meets them with the polynomial alone (the correction takes only what the weight
    EPSILON = 1e-4 leaves: 1e-4 of s allowed), the corrected shear balances them to round-off,
    and at 50 points per facet it stays within the polynomial whose Bernstein coefficients
    are s at the Greville points (s itself where s is concave along the facet)."""
    scene, solution, interior, clamped, _ = stick_slip_mixed
    trace = solution.trace

    def balance(pressure):
        return traction_balance(interior, trace, pressure, contact_tangent(trace))

    s = coefficient_bounds(scene, trace, 1)
    left = balance(bernstein_polynomial(0.5 * s))
    shear = bounded_shear(scene, solution, left, clamped, balance)
    assert np.abs(shear.delta).max() <= 1e-4 * s.max()
    wanted = tangential(trace, left, clamped)
    got = tangential(trace, balance(shear), clamped)
    assert np.linalg.norm(got - wanted) <= 1e-10 * np.linalg.norm(wanted)
    t = np.linspace(0, 1, 50)
    assert (np.abs(shear(t)) - bernstein_polynomial(s)(t)).max() <= 1e-4 * s.max()


def test_the_mixed_methods_excess_shear_is_halved(stick_slip_mixed):
    """stick-slip, mixed, P1, 2178 DOFs: the multiplier exceeds s between the nodes of its
    mesh, and its corrected projection has ||(|sigma*_t| - s)_+|| = 2.67e-4 / C_T; the shear
    the bound chooses has the same tangential moments and 1.39e-4 (measured; 0.7 of it
    allowed)."""
    scene, solution, interior, clamped, chosen = stick_slip_mixed
    trace = solution.trace

    def balance(pressure):
        return traction_balance(interior, trace, pressure, contact_tangent(trace))

    raw = balanced_shear(solution, balance(chosen) - balance(raw_shear(solution).pressure),
                         clamped)
    wanted = tangential(trace, balance(chosen), clamped)
    assert np.allclose(tangential(trace, balance(raw), clamped), wanted, rtol=0,
                       atol=1e-10 * np.abs(wanted).max())
    assert excess_norm(scene, solution, chosen) <= 0.7 * excess_norm(scene, solution, raw)

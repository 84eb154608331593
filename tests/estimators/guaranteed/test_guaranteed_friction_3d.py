"""The friction terms of the guaranteed bound on tetrahedra (docs/theory.md, 17.5, "On
tetrahedra"): sigma*_t in the triangles' planes, balancing every contact vertex, and N_t and
B_t against scikit-fem's evaluation of u_h on the contact triangles."""

from dataclasses import replace

import numpy as np
import pytest
from skfem import FacetBasis

from bench.measure.discretisation_error import exact_errors
from estimators import get_estimator
from estimators.base import ESTIMATORS
from estimators.guaranteed.equilibrated_3d import equilibrate
from estimators.guaranteed.guaranteed_friction_3d import (
    SurfaceShear,
    balanced_shear,
    friction_bound,
    in_plane,
    shear_balance,
)
from formulations import get_formulation, solve
from formulations.contact.reference_facets import triangle_rule
from formulations.registry import FORMULATIONS
from scenes import get_scene

SCENE = get_scene("stick-slip-3d")
FRICTIONAL = [name for name in FORMULATIONS.names()
              if 3 in FORMULATIONS.meta(name, "friction_dims")]


@pytest.fixture(scope="module")
def solved():
    solution = solve(get_formulation("vi")(SCENE, SCENE.mesh.refined(1)), "active-set")
    return solution, equilibrate(SCENE, solution)


def random_shear(surface, seed: int = 0) -> SurfaceShear:
    corners = np.random.default_rng(seed).normal(size=(3, surface.size, 3))
    return SurfaceShear(in_plane(corners, surface.normal).transpose(0, 2, 1))


def test_the_shear_at_points_is_the_shear_at_their_local_coordinates(solved):
    surface = solved[0].trace
    shear = random_shear(surface)
    t, _ = triangle_rule(4)
    np.testing.assert_allclose(shear.at(surface, surface.points(t)), shear(t), atol=1e-12)
    # in the plane of its triangle at every point
    assert np.abs((shear(t) * surface.normal[:, :, None]).sum(axis=0)).max() < 1e-12


def test_the_correction_balances_every_contact_vertex_along_the_tangents(solved):
    # the hat moments (by the RT boundary fluxes) of the balanced shear are the tangential
    # part of the defect at every contact vertex off Gamma_D (Gamma_C is the plane z = -1)
    solution, (_, interior, *_) = solved
    surface = solution.trace
    n_v = surface.mesh.p.shape[1]
    clamped = np.zeros(n_v, dtype=bool)
    clamped[surface.mesh.facets[:, SCENE.dirichlet_facets(surface.mesh)].ravel()] = True
    defect = np.random.default_rng(1).normal(size=(n_v, 3))
    start = random_shear(surface, seed=2)
    shear = balanced_shear(surface, start,
                           defect - shear_balance(interior, surface, start), clamped)
    on = np.unique(surface.vertices)
    on = on[~clamped[on]]
    moments = shear_balance(interior, surface, shear)
    np.testing.assert_allclose(moments[on][:, :2], defect[on][:, :2], rtol=1e-10, atol=1e-12)
    assert np.abs(moments[:, 2]).max() < 1e-12  # no normal part
    assert np.abs(moments[~np.isin(np.arange(n_v), np.unique(surface.vertices))]).max() == 0


@pytest.mark.parametrize("slide", [0.0, 0.02])
def test_the_friction_terms_agree_with_scikit_fem_on_the_contact_triangles(solved, slide):
    # the scene's own obstacle stays (its slip is in u); a slide w = 0.02 e_x moves xi_h
    solution, (*_, tractions, _) = solved
    law = replace(SCENE.friction, slide=slide)
    scene, surface = replace(SCENE, friction=law), solution.trace
    shear, d = tractions.shear, tractions.bounds[0].field
    basis = FacetBasis(surface.mesh, solution.elasticity.basis.elem, facets=surface.facets,
                       intorder=12)
    x = np.asarray(basis.global_coordinates())                            # (3, n_f, nq)
    u = np.asarray(basis.interpolate(solution.u))
    n = surface.normal[:, :, None]
    xi = u - np.array([law.slide, 0.0, 0.0])[:, None, None]
    xi = xi - (xi * n).sum(axis=0) * n
    weights = np.array([np.linalg.solve(  # barycentric in the plane z = -1
        np.vstack([surface.mesh.p[:2, surface.vertices[:, f]], np.ones(3)]),
        np.vstack([x[:2, f], np.ones(x.shape[2])])) for f in range(surface.size)])
    nodal = np.einsum("icf,fcq->ifq", d.nodal[:, surface.vertices], weights)
    y = xi + nodal - (nodal * n).sum(axis=0) * n
    sigma = shear.at(surface, x)
    s = law.slip_bound_at(x)
    excess = np.maximum(np.linalg.norm(sigma, axis=0) - s, 0.0)
    integrand = (s * np.linalg.norm(y, axis=0) + (sigma * y).sum(axis=0)
                 + excess * np.linalg.norm(xi, axis=0))
    dx = np.asarray(basis.dx)
    terms = friction_bound(scene, solution, shear, d)
    # the rules differ (degree 8 and 12) on integrands with kinks (|xi| and |y| at 0, the
    # excess at |sigma| = s): measured 0.2 % apart; a wrong sign, slide or part is O(1)
    assert terms.complementarity == pytest.approx((integrand * dx).sum(), rel=1e-2)
    assert terms.excess == pytest.approx(np.sqrt((excess**2 * dx).sum()), rel=1e-2)
    assert terms.per_element.sum() >= abs(terms.complementarity) * (1 - 1e-12)


@pytest.mark.parametrize("formulation", [
    name if name == "vi" else pytest.param(name, marks=pytest.mark.slow)  # ~4 s each
    for name in FRICTIONAL])
def test_the_bound_is_above_the_exact_error_with_tresca_friction_in_3d(formulation, solved):
    solution = (solved[0] if formulation == "vi" else
                solve(get_formulation(formulation)(SCENE, SCENE.mesh.refined(1)), "active-set"))
    estimate = get_estimator("equilibrated")(SCENE, solution)
    error = exact_errors(SCENE, solution).energy_error
    # a bound, not an estimate: no tolerance beyond the exact error's quadrature (~1e-8)
    assert estimate.eta >= error * (1 - 1e-6), (estimate.eta, error)
    assert estimate.eta <= 5 * error  # and a useful one: measured 2.19 .. 2.77 on this mesh
    parts = estimate.bound
    # the shear is charged: the excess and B_t are parts of eta (measured > 1e-4 each)
    assert parts.excess_shear > 0 and parts.friction_complementarity > 0


def test_coulomb_is_refused_by_the_bound_in_3d_and_tresca_is_not():
    why = ESTIMATORS.why_not("equilibrated", scene=get_scene("stick-slip-3d",
                                                             friction="coulomb"))
    assert why is not None and "Tresca friction only" in why
    assert ESTIMATORS.why_not("equilibrated", scene=SCENE) is None

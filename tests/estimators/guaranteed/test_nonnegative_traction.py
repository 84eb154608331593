"""The non-negative auxiliary contact traction of the guaranteed bound (docs/theory.md, 13.3)."""

import numpy as np
import pytest
from scipy.special import comb

from estimators import get_estimator
from estimators.guaranteed.contact_extension import vertex_normals
from estimators.guaranteed.equilibrated import equilibrate
from estimators.guaranteed.guaranteed_contact import traction_balance
from estimators.guaranteed.nonnegative_traction import hat_moments, nonnegative_pressure
from formulations import get_formulation, solve
from formulations.contact.reference_facets import gauss_legendre
from scenes import get_scene


@pytest.fixture(scope="module")
def hertz_vi():
    scene = get_scene("hertz")
    solution = solve(get_formulation("vi")(scene, scene.mesh.refined(3)), "active-set")
    clamped = equilibrate(scene, solution)[5]
    return scene, solution, clamped


@pytest.mark.parametrize("k", [1, 2, 3])
def test_hat_moments_are_the_integrals_of_bernstein_times_hat(hertz_vi, k):
    """Against Gauss quadrature of B_j psi_a on every facet (exact for degree k + 1)."""
    _, solution, _ = hertz_vi
    trace = solution.trace
    t, w = gauss_legendre(k + 2)
    bernstein = np.array([comb(k, j) * t**j * (1 - t) ** (k - j) for j in range(k + 1)])
    G = hat_moments(trace, k).toarray()
    for side, hat in enumerate((1 - t, t)):
        expected = trace.length[:, None] * (bernstein * hat * w).sum(axis=1)   # (n_f, k + 1)
        rows = G[trace.vertices[side]].reshape(trace.size, trace.size, k + 1)
        got = rows[np.arange(trace.size), np.arange(trace.size)]
        # a vertex shared by two facets sums both; the facet's own share is its diagonal block
        assert np.allclose(got, expected, rtol=1e-13, atol=0)


def test_the_pressure_is_non_negative_and_has_the_reactions_moments(hertz_vi):
    """Non-negative (Bernstein coefficients >= 0) at 50 points per facet, and its moments
    against the hats of the contact vertices are vi's nodal reactions to the least squares'
    weight EPSILON (relative 1e-4 allowed; measured ~2e-6)."""
    scene, solution, clamped = hertz_vi
    trace = solution.trace
    _, interior, *_ = equilibrate(scene, solution)
    reaction = interior.total  # the per-vertex balance of the traction equilibrate chose
    pressure = nonnegative_pressure(trace, reaction, clamped, 1)
    values = pressure(np.linspace(0, 1, 50))
    assert values.min() >= -1e-12 * values.max()  # round-off of the Legendre form
    on = np.unique(np.concatenate(trace.vertices))
    on = on[~clamped[on]]
    balance = traction_balance(interior, trace, pressure)
    moments = -(balance[on] * vertex_normals(trace)[:, on].T).sum(1)
    wanted = -(reaction[on] * vertex_normals(trace)[:, on].T).sum(1)
    assert np.linalg.norm(moments - wanted) <= 1e-4 * np.linalg.norm(wanted)


def test_the_bound_takes_it_where_the_reactions_representative_changes_sign(hertz_vi):
    """hertz, vi, 16 770 DOFs: the L2 representative of the reactions had C_T ||lambda*_-||
    = 0.034 against A = 0.027; the non-negative traction leaves no negative part (round-off of
    its correction: relative 1e-5 allowed, 1.2e-6 measured) and a smaller bound (measured
    0.0744 without this candidate, 0.0478 with it)."""
    scene, solution, _ = hertz_vi
    estimate = get_estimator("equilibrated")(scene, solution)
    assert estimate.bound.negative_traction <= 1e-5 * estimate.eta
    assert estimate.eta < 0.07

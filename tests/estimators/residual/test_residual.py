"""The residual estimator on problems whose answers are known."""

import numpy as np
import pytest

from conftest import square_scene
from estimators import get_estimator
from formulations import get_formulation, solve
from scenes import get_scene

estimate = get_estimator("residual")
discretise = get_formulation("mixed")


def solved(scene, mesh):
    sol = solve(discretise(scene, mesh), "reference")
    assert sol.status == "ok", sol.reason
    return sol


def test_no_contact_gives_exactly_zero_contact_terms(free_scene):
    sol = solved(free_scene, free_scene.mesh.refined(2))
    u_n = sol.normal_displacement(np.array([0.0, 1.0]))
    assert 0 < np.abs(u_n).max() < 0.5  # the body moves, far from the obstacle at 1.0
    est = estimate(free_scene, sol)
    # exact, no tolerance: lambda_h = 0 and (g - u_n)_- = 0 exactly when nothing touches
    assert est.eta_geometric == 0.0 and est.eta_complementarity == 0.0
    assert est.eta_0 > 0 and est.eta == pytest.approx(est.eta_0, rel=1e-15)


def test_discrete_exact_solution_has_zero_estimate(compression_scene):
    sol = solved(compression_scene, compression_scene.mesh.refined(1))
    est = estimate(compression_scene, sol)
    # u_h is the exact linear field up to the solver's 1e-9 tolerance, so every residual term
    # vanishes to that level; compare with the size of the stress it balances: E delta / 2 = 5
    energy_norm = np.sqrt(sol.u @ sol.elasticity.K @ sol.u)
    assert est.eta < 1e-6 * energy_norm
    assert est.eta_geometric < 1e-6 * energy_norm and est.eta_complementarity < 1e-6 * energy_norm


def test_wrong_pressure_is_detected_by_the_contact_edge_residual(compression_scene):
    """Replacing lambda_h by 0 must leave exactly the residual ||sigma_nn||_e on Gamma_C."""
    from dataclasses import replace

    sol = solved(compression_scene, compression_scene.mesh.refined(1))
    wrong = replace(sol, pressure=lambda t: np.zeros((sol.trace.size, len(t))))
    est = estimate(compression_scene, wrong)
    # sum_e h_e ||sigma_nn||_e^2 / E = sum_e h_e^2 (E delta/2)^2 / E with h_e = 0.25, 8 facets
    expected = np.sqrt(8 * 0.25**2 * 5.0**2 / 1000.0)
    assert est.eta_0 == pytest.approx(expected, rel=1e-6)


def test_indicators_sum_to_eta_squared_and_localise_at_contact():
    scene = get_scene("paper")
    sol = solved(scene, scene.mesh.refined(3))
    est = estimate(scene, sol)
    assert est.indicators.sum() == pytest.approx(est.eta**2, rel=1e-12)
    assert (est.indicators >= 0).all()  # exact: sums of squares
    assert est.eta**2 == pytest.approx(est.eta_0**2 + est.eta_geometric**2
                                       + est.eta_complementarity**2, rel=1e-14)
    # the largest indicator sits at the bottom (contact zone) or at the clamped corners
    worst = est.indicators.argmax()
    y = sol.elasticity.mesh.p[1, sol.elasticity.mesh.t[:, worst]]
    assert y.min() < -0.5 or y.max() > 0.5


def test_estimator_is_invariant_under_young_modulus_scaling():
    """With f = q = 0 the displacement does not depend on E and every term of eta^2 scales like
    E (energy units), so eta / sqrt(E) is the same for E = 1 and E = 70000."""
    values = []
    for E in (1.0, 70000.0):
        scene = get_scene("paper", young_modulus=E)
        est = estimate(scene, solved(scene, scene.mesh.refined(2)))
        values.append(np.array([est.eta, est.eta_0, est.eta_geometric,
                                est.eta_complementarity]) / np.sqrt(E))
    assert values[0] == pytest.approx(values[1], rel=1e-6)


def test_geometric_term_matches_hand_computation():
    """u_h = 0 (nothing pushes the body; gap -0.1 on x > 0 only is not enforced because the
    pressure is replaced) gives w = (g)_- = -0.1 on (0, 1): ||w||_0^2 = 0.01, ||w'||_0 = 0."""
    from dataclasses import replace

    scene = square_scene(lambda x: np.where(x[0] > 0, -0.1, 0.2), young_modulus=1.0)
    sol = solved(scene, scene.mesh.refined(1))
    zero = replace(sol, u=np.zeros_like(sol.u),
                   pressure=lambda t: np.ones((sol.trace.size, len(t))))
    est = estimate(scene, zero)
    # ||w||_{1/2}^2 ~ ||w||_0 ||w||_1 = 0.1 * 0.1 (E = 1); (lambda, w) = 1 * (-0.1) * 1
    assert est.eta_geometric**2 == pytest.approx(0.01, rel=1e-12)
    assert est.eta_complementarity**2 == pytest.approx(0.1, rel=1e-12)

"""The penalty formulation: non-negative pressure, penetration ~ eps_0, scale invariance."""

import numpy as np
import pytest

from bench.measure.difference import solution_difference
from formulations import get_formulation, solve
from formulations.contact.reference_facets import gauss_legendre
from formulations.solvers import semismooth_newton
from formulations.solvers.backends import available_backends
from scenes import get_scene


def penalty_solution(epsilon_0, young_modulus=70000.0, refinements=3):
    scene = get_scene("paper", young_modulus=young_modulus)
    disc = get_formulation("penalty")(scene, scene.mesh.refined(refinements),
                                      epsilon_0=epsilon_0)
    sol = solve(disc, "active-set")
    assert sol.status == "ok", sol.reason
    return sol


def max_penetration(sol):
    # penetration against the interpolated gap, lambda_h * eps, at many points per facet
    t = np.linspace(0.0, 1.0, 11)
    return float((sol.pressure(t) * sol.details.epsilon[:, None]).max())


def test_pressure_is_non_negative_and_matches_the_active_set():
    sol = penalty_solution(1e-3)
    pressure = sol.pressure(np.linspace(0.0, 1.0, 7))
    # exact, no tolerance: lambda_h is a positive part (np.maximum) divided by eps > 0
    assert pressure.min() >= 0.0 and pressure.max() > 0.0
    assert sol.active_constraints > 0


def test_penetration_shrinks_linearly_with_eps_0():
    # penetration = eps lambda = eps_0 h lambda / E, and lambda converges as eps_0 -> 0, so one
    # decade of eps_0 must remove (close to) one decade of penetration
    penetrations = [max_penetration(penalty_solution(e)) for e in (1e-1, 1e-2, 1e-3, 1e-4)]
    ratios = np.array(penetrations[:-1]) / np.array(penetrations[1:])
    assert (ratios > 5.0).all(), penetrations


def test_eps_0_means_the_same_for_every_young_modulus():
    # eps = eps_0 h / E: the displacement does not depend on E (pure Dirichlet-obstacle
    # loading), the pressure scales with E
    soft, stiff = penalty_solution(1e-3, 1.0), penalty_solution(1e-3, 70000.0)
    assert soft.u == pytest.approx(stiff.u, rel=1e-8, abs=1e-12)
    assert 70000.0 * soft.contact_force() == pytest.approx(stiff.contact_force(), rel=1e-8)


def test_bad_eps_0_is_refused():
    scene = get_scene("paper")
    with pytest.raises(ValueError, match=r"epsilon_0=0.0 is not a finite number > 0"):
        get_formulation("penalty")(scene, scene.mesh, epsilon_0=0.0)


def test_penalty_integral_uses_the_stated_gauss_rule():
    # sum of the slack weights D_q / (E / eps_0) over one facet is 1 (Gauss weights on [0, 1])
    scene = get_scene("paper")
    disc = get_formulation("penalty")(scene, scene.mesh, epsilon_0=1e-3)
    n = disc.elasticity.free.size
    D = disc.qp.K.diagonal()[n:] / (70000.0 / 1e-3)
    _, w = gauss_legendre(2)
    assert D == pytest.approx(np.tile(w, D.size // 2), rel=1e-14)


@pytest.mark.parametrize("backend", available_backends())
def test_the_fast_solve_is_the_penalised_equation_on_both_routes(monkeypatch, backend):
    scene = get_scene("paper")
    disc = get_formulation("penalty")(scene, scene.mesh.refined(3))
    assert disc.system is not None and disc.system.ns == 0  # no sigma_nn term
    reference = solve(disc, "reference")
    answers = []
    for threshold in (10**9, 0):  # condensed onto the Gauss points, then sparse Newton steps
        monkeypatch.setattr(semismooth_newton, "SPARSE_NEWTON_FROM", threshold)
        sol = solve(disc, "active-set", backend=backend)
        # the nonlinear residual of an exact active set: round-off times the penalty's
        # conditioning (~1e3 relative to K's; measured 1e-13 .. 5e-10 up to 5e5 DOFs)
        assert sol.status == "ok" and sol.residuals.stationarity < 1e-9, sol.reason
        answers.append(sol)
    condensed, stepped = answers
    energy, pressure = solution_difference(disc, condensed, stepped)
    assert energy < 1e-10 and pressure < 1e-8  # the same equation solved twice: round-off
    # against Clarabel on the slack QP (tolerance 1e-10): the 1e-7 / 1e-6 of the other checks
    energy, pressure = solution_difference(disc, condensed, reference)
    assert energy < 1e-7 and pressure < 1e-5


@pytest.mark.parametrize("scene_name, refinements", [("hertz-3d", 0), ("paper", 2)])
def test_a_higher_order_pressure_stays_within_its_samples(scene_name, refinements):
    """P2: lambda_h between the quadrature points never exceeds the facet's largest value
    there (a quadratic through interior points overshoots towards the corners where the
    zone's edge crosses the facet; unbounded, hertz-3d's peak was 3.25 x Hertz's)."""
    scene = get_scene(scene_name)
    sol = solve(get_formulation("penalty")(scene, scene.mesh.refined(refinements), order=2),
                "active-set")
    trace = sol.trace
    t, _ = trace.rule(4)  # the 6 points of the P2 penalty on triangles (p + 1 = 3 in 2D)
    if scene.dim == 2:
        t = gauss_legendre(3)[0]
    samples = sol.pressure(t)
    grid = (np.array(np.meshgrid(np.linspace(0, 1, 9), np.linspace(0, 1, 9))).reshape(2, -1)
            if scene.dim == 3 else np.linspace(0.0, 1.0, 41))
    if scene.dim == 3:
        grid = grid[:, grid.sum(axis=0) <= 1.0]  # the reference triangle
    # the clip itself: exact up to the round-off of evaluating the samples twice
    assert (sol.pressure(grid).max(axis=1) <= samples.max(axis=1) * (1 + 1e-12)).all()
    assert samples.max() > 0

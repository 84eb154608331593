"""The fast active-set solver: exact LCP answers, failure reporting, agreement with the
reference solver."""

import numpy as np
import pytest

from formulations import get_formulation, solve
from formulations.solvers.backends import available_backends, iterative
from formulations.solvers.lcp import pdas
from scenes import get_scene


def test_pdas_solves_a_diagonal_lcp_exactly():
    # S = diag(d): lambda_i = max(r_i, 0) / d_i is the unique solution
    d, r = np.array([1.0, 2.0, 4.0, 0.5]), np.array([1.0, -3.0, 2.0, -0.1])
    result = pdas(np.diag(d), r, np.zeros(4, bool), max_iter=10)
    assert result.status == "ok" and result.iterations <= 2
    assert result.lam == pytest.approx(np.maximum(r, 0) / d, abs=0)


def test_pdas_reports_non_convergence_instead_of_looping():
    S = np.array([[2.0, -1.0, 0.0], [-1.0, 2.0, -1.0], [0.0, -1.0, 2.0]])
    r = np.array([1.0, -5.0, 1.0])
    result = pdas(S, r, np.ones(3, bool), max_iter=1)
    assert result.status == "failed" and result.iterations == 1
    assert "still changing" in result.reason


def paper_meshes():
    scene = get_scene("paper")
    yield "uniform-544", scene.mesh.refined(2)
    yield "uniform-8320", scene.mesh.refined(4)
    rng = np.random.default_rng(2)
    mesh = scene.mesh.refined(2)
    for _ in range(4):  # a graded mesh, refined towards the contact zone
        y = mesh.p[1, mesh.t].mean(axis=0)
        candidates = np.flatnonzero(y < -0.5)
        mesh = mesh.refined(np.sort(rng.choice(candidates, candidates.size // 2, replace=False)))
    yield "graded", mesh


@pytest.mark.parametrize("backend", available_backends())
@pytest.mark.parametrize("label, mesh", list(paper_meshes()), ids=lambda v: v
                         if isinstance(v, str) else "")
def test_active_set_agrees_with_reference(label, mesh, backend):
    scene = get_scene("paper")
    disc = get_formulation("mixed")(scene, mesh)
    fast, reference = solve(disc, "active-set", backend=backend), solve(disc, "reference")
    assert fast.status == "ok", fast.reason
    assert fast.backend == backend
    assert reference.status == "ok", reference.reason
    # a direct back-end is exact: KKT residuals at round-off. An iterative one stops its Krylov
    # solve at a relative residual of 1e-10 (backends/amg.py RTOL), so stationarity is only
    # bounded by that; the other residuals stay at round-off either way
    stationarity_bound = 1e-10 if iterative(backend) else 1e-12
    residuals = fast.residuals
    assert residuals.stationarity < stationarity_bound, residuals
    assert max(residuals.violation, residuals.dual_violation, residuals.complementarity) < 1e-12
    free, K = disc.elasticity.free, disc.qp.K
    du = fast.u[free] - reference.u[free]
    energy_diff = np.sqrt(du @ K @ du) / np.sqrt(reference.u[free] @ K @ reference.u[free])
    lam_fast, lam_ref = fast.multipliers, reference.multipliers
    lam_diff = np.abs(lam_fast - lam_ref).max() / np.abs(lam_ref).max()
    # Clarabel runs at 1e-10 relative gap/feasibility (formulations/solvers/reference.py), which
    # was measured to leave ~3e-9 (energy norm) and ~1.3e-8 (max lambda) here; 1e-7 and 1e-6
    # allow for that with margin while any real disagreement (a wrong active set) is >= 1e-3
    assert energy_diff <= 1e-7, energy_diff
    assert lam_diff <= 1e-6, lam_diff
    assert fast.active_constraints == reference.active_constraints


def test_warm_start_from_the_solution_needs_one_iteration():
    from formulations.solvers.active_set import solve_active_set

    scene = get_scene("paper")
    qp = get_formulation("mixed")(scene, scene.mesh.refined(3)).qp
    cold = solve_active_set(qp)
    warm = solve_active_set(qp, warm_start=cold.multipliers)
    assert cold.status == warm.status == "ok"
    assert cold.iterations > 1 and warm.iterations == 1  # the active set is right at once
    assert warm.multipliers == pytest.approx(cold.multipliers, rel=1e-12, abs=0)

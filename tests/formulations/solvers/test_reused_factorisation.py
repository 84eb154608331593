"""Sparse Newton steps that reuse an earlier factorisation: CG preconditioned by J_0^-1 on a
Jacobian that differs from J_0 in k rank-one terms."""

import numpy as np
import pytest
from scipy import sparse

from formulations.solvers import reused_factorisation
from formulations.solvers.backends import factorise
from formulations.solvers.reused_factorisation import ReusedFactorisation, preconditioned_cg

BACKEND = "splu"  # any direct back-end: the reuse does not depend on which


def jacobian(K, T, active):
    """K + T' D_A T with unit weights on the active points."""
    return (K + T.T @ sparse.diags(active.astype(float)) @ T).tocsr()


@pytest.fixture
def problem():
    rng = np.random.default_rng(3)
    n, nq = 400, 120
    K = sparse.diags([-1.0, 2.5, -1.0], [-1, 0, 1], shape=(n, n)).tocsr()  # SPD
    T = sparse.random(nq, n, density=0.02, random_state=rng, format="csr") * 10.0
    return K, T, rng.standard_normal(n)


def test_cg_needs_at_most_k_plus_one_steps_for_k_changed_points(problem):
    K, T, b = problem
    active = np.zeros(T.shape[0], dtype=bool)
    active[:60] = True
    solve_0 = factorise(jacobian(K, T, active), BACKEND)
    for k in (1, 5, 20):
        changed = active.copy()
        changed[60:60 + k] = True
        J = jacobian(K, T, changed)
        x, iterations = preconditioned_cg(J, b, solve_0, 200)
        # exact arithmetic: k + 1; two more for round-off at a residual of 1e-13
        assert iterations <= k + 3, (k, iterations)
        np.testing.assert_allclose(J @ x, b, rtol=0, atol=1e-12 * np.linalg.norm(b))


def test_a_step_refactorises_when_cg_runs_out_of_its_budget(problem):
    K, T, b = problem
    direct = ReusedFactorisation(BACKEND)
    active = np.zeros(T.shape[0], dtype=bool)
    for count, budget, factorisations in ((10, None, 1), (12, 1000, 1), (100, 20, 2)):
        if budget is not None:  # set by the timing of the factorisation otherwise
            direct.budget = budget
        active[:count] = True
        J = jacobian(K, T, active)
        x = direct(J, active, b)
        assert direct.factorisations == factorisations, count
        np.testing.assert_allclose(J @ x, b, rtol=0, atol=1e-12 * np.linalg.norm(b))
    assert len(direct.iterations) == 2 and direct.iterations[-1] == 20  # reused, then gave up


def test_a_step_with_many_changed_points_for_its_budget_does_not_try_cg(problem):
    K, T, b = problem
    direct = ReusedFactorisation(BACKEND)
    active = np.zeros(T.shape[0], dtype=bool)
    direct(jacobian(K, T, active), active, b)
    direct.budget = 4
    active[:21] = True  # 21 > 5 x 4 changed points: a factorisation at once
    J = jacobian(K, T, active)
    x = direct(J, active, b)
    assert direct.factorisations == 2 and direct.iterations == []
    np.testing.assert_allclose(J @ x, b, rtol=0, atol=1e-12 * np.linalg.norm(b))


def test_a_reused_step_that_stalls_is_solved_by_a_new_factorisation(problem, monkeypatch):
    K, T, b = problem
    monkeypatch.setattr(reused_factorisation, "SLACK", -1)  # CG gets k iterations: too few
    direct = ReusedFactorisation(BACKEND)
    active = np.zeros(T.shape[0], dtype=bool)
    direct(jacobian(K, T, active), active, b)
    direct.budget = 1000  # not the limit here
    active[:8] = True
    J = jacobian(K, T, active)
    x = direct(J, active, b)
    assert direct.factorisations == 2 and direct.iterations == [8]
    np.testing.assert_allclose(J @ x, b, rtol=0, atol=1e-12 * np.linalg.norm(b))

"""The LCP iterations behind the active-set solver, and its safeguard when they cycle."""

import numpy as np
import pytest

from formulations.kkt import qp_residuals
from formulations.solvers.active_set import cycling_qp, solve_active_set
from formulations.solvers.backends import available_backends, condenses
from formulations.solvers.lcp import CYCLING_EXAMPLE, least_index_pivoting, pdas

CYCLING_S, CYCLING_R, CYCLING_START = CYCLING_EXAMPLE


def assert_solves_lcp(S, r, lam, tol=1e-12):
    y = S @ lam - r
    scale = np.abs(r).max()
    # lam is assembled from exact zeros and solves of a small system: >= 0 up to tol * scale
    assert lam.min() >= -tol * scale and y.min() >= -tol * scale
    assert abs(lam @ y) <= tol * scale**2 * 10


def test_plain_pdas_cycles_on_this_spd_lcp():
    assert np.linalg.eigvalsh(CYCLING_S).min() > 0  # SPD, so the LCP has a unique solution
    result = pdas(CYCLING_S, CYCLING_R, CYCLING_START.copy(), max_iter=100)
    assert result.status == "failed" and result.cycled and "cycles" in result.reason
    assert all(c > 0 for c in result.changes)


def test_least_index_pivoting_solves_it_and_random_spd_lcps():
    result = least_index_pivoting(CYCLING_S, CYCLING_R, CYCLING_START.copy(), max_iter=100)
    assert result.status == "ok" and result.changes[-1] == 0
    assert_solves_lcp(CYCLING_S, CYCLING_R, result.lam)
    rng = np.random.default_rng(1)
    for _ in range(300):  # Murty 1974: finite for every P-matrix, from any start
        n = int(rng.integers(2, 9))
        A = rng.normal(size=(n, n))
        S, r = A @ A.T + 0.01 * np.eye(n), rng.normal(size=n)
        result = least_index_pivoting(S, r, rng.random(n) > 0.5, max_iter=10 * 2**n)
        assert result.status == "ok"
        assert_solves_lcp(S, r, result.lam, tol=1e-9)


@pytest.mark.parametrize("backend", available_backends())
def test_the_solver_safeguards_a_cycling_iteration(backend):
    qp = cycling_qp()
    answer = solve_active_set(qp, warm_start=CYCLING_START.astype(float), backend=backend)
    assert answer.status == "ok"
    residuals = qp_residuals(qp, answer.u, answer.multipliers)
    # least-index pivoting is exact; the reference fallback is Clarabel at 1e-10
    assert max(vars(residuals).values()) < 1e-8
    expected = least_index_pivoting(CYCLING_S, CYCLING_R, CYCLING_START.copy(), 100).lam
    assert answer.multipliers == pytest.approx(expected, abs=1e-7)
    if condenses(backend):  # the condensed route cycles and pivots
        assert answer.diagnostics.cycled
        assert answer.diagnostics.safeguard == "least-index pivoting"
        assert "cycles" in answer.reason and "least-index" in answer.reason


@pytest.mark.parametrize("backend", available_backends())
def test_an_exhausted_iteration_is_safeguarded_and_says_so(backend):
    qp = cycling_qp()
    answer = solve_active_set(qp, warm_start=CYCLING_START.astype(float), backend=backend,
                              max_iter=1)
    assert answer.status == "ok" and "still changing" in answer.reason
    expected = "least-index pivoting" if condenses(backend) else "reference fallback"
    assert answer.diagnostics.safeguard == expected
    assert (answer.backend == "clarabel") == (expected == "reference fallback")


@pytest.mark.parametrize("backend", available_backends())
def test_dependent_active_rows_are_a_reason_not_an_exception(backend):
    # two identical constraint rows both active: B K^-1 B' (and the saddle-point matrix of
    # the augmented route) is singular; the iteration says so and the reference answers
    from scipy import sparse

    from formulations.base import ContactQP
    qp = ContactQP(K=sparse.identity(2, format="csr"), F=np.array([1.0, 1.0]),
                   B=sparse.csr_matrix(np.array([[1.0, 0.0], [1.0, 0.0]])),
                   G=np.array([0.5, 0.5]), row_scale=np.ones(2), objective_scale=1.0)
    answer = solve_active_set(qp, warm_start=np.ones(2), backend=backend)
    assert answer.status == "ok" and "linearly dependent" in answer.reason
    assert answer.diagnostics.safeguard == "reference fallback"
    # u = (0.5, 1): the first component stops at the obstacle (Clarabel's tolerance 1e-8)
    assert answer.u == pytest.approx([0.5, 1.0], abs=1e-7)


def test_pdas_reports_a_singular_active_block():
    from formulations.solvers.lcp import SINGULAR
    S, r = np.ones((2, 2)), np.ones(2)
    for method in (pdas, least_index_pivoting):
        result = method(S, r, np.array([True, True]), 10)
        assert result.status == "failed" and result.reason == SINGULAR

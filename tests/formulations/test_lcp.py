"""The LCP iterations behind the active-set solver, and its safeguard when they cycle."""

import numpy as np
import pytest
from scipy import sparse

from formulations.base import ContactQP
from formulations.kkt import qp_residuals
from formulations.solvers.active_set import solve_active_set
from formulations.solvers.backends import available_backends
from formulations.solvers.lcp import least_index_pivoting, pdas

# found by a random search over SPD matrices (seed 0, trial 2392): from this start the plain
# primal-dual active set method revisits an active set after 5 iterations
CYCLING_S = np.array([
    [3.33914076, -1.96172517, -0.00715703, -1.06847366, 1.66118594],
    [-1.96172517, 3.25846728, 0.04343212, -0.39452142, -1.75831306],
    [-0.00715703, 0.04343212, 6.52869201, -1.95694266, -1.46103878],
    [-1.06847366, -0.39452142, -1.95694266, 2.59830682, 1.04405007],
    [1.66118594, -1.75831306, -1.46103878, 1.04405007, 1.9634999]])
CYCLING_R = np.array([0.02812848, -2.17454055, 1.15602742, -0.07672046, 0.86086229])
CYCLING_START = np.array([False, True, False, True, False])


def assert_solves_lcp(S, r, lam, tol=1e-12):
    y = S @ lam - r
    scale = np.abs(r).max()
    assert lam.min() >= 0 and y.min() >= -tol * scale and abs(lam @ y) <= tol * scale**2 * 10


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


def _cycling_qp() -> ContactQP:
    # K = S^-1, B = I, F = 0, G = -r: the condensed system B K^-1 B' is exactly CYCLING_S
    K = sparse.csr_matrix(np.linalg.inv(CYCLING_S))
    return ContactQP(K=K, F=np.zeros(5), B=sparse.identity(5, format="csr"), G=-CYCLING_R,
                     row_scale=np.ones(5), objective_scale=1.0)


@pytest.mark.parametrize("backend", available_backends())
def test_the_solver_safeguards_a_cycling_iteration(backend):
    qp = _cycling_qp()
    answer = solve_active_set(qp, warm_start=CYCLING_START.astype(float), backend=backend)
    assert answer.status == "ok"
    residuals = qp_residuals(qp, answer.u, answer.multipliers)
    # least-index pivoting is exact; the reference fallback is Clarabel at 1e-10
    assert max(vars(residuals).values()) < 1e-8
    expected = least_index_pivoting(CYCLING_S, CYCLING_R, CYCLING_START.copy(), 100).lam
    assert answer.multipliers == pytest.approx(expected, abs=1e-7)
    if backend == "cholmod":  # the condensed route cycles and pivots
        assert answer.diagnostics["cycled"]
        assert answer.diagnostics["safeguard"] == "least-index pivoting"
        assert "cycles" in answer.reason and "least-index" in answer.reason


@pytest.mark.parametrize("backend", available_backends())
def test_an_exhausted_iteration_is_safeguarded_and_says_so(backend):
    qp = _cycling_qp()
    answer = solve_active_set(qp, warm_start=CYCLING_START.astype(float), backend=backend,
                              max_iter=1)
    assert answer.status == "ok" and "still changing" in answer.reason
    expected = {"cholmod": "least-index pivoting", "splu": "reference fallback"}[backend]
    assert answer.diagnostics["safeguard"] == expected
    assert (answer.backend == "clarabel") == (expected == "reference fallback")

"""The primal-dual active set iteration on the augmented (saddle-point) system, for back-ends
that cannot give the Schur complement of K on the contact DOFs cheaply (scipy's SuperLU).

Each iteration factorises [[K, B_A'], [B_A, 0]] for the current active set A and solves for
(u, lambda_A); lambda is 0 off A. The next active set keeps the rows of A with lambda_i > 0 and
adds the inactive rows the new u violates, B_i u > G_i -- the same rule as the condensed
iteration (on A the slack vanishes and off A the multiplier does, so the semismooth Newton
constant drops out). With nested iteration the active set is nearly right from the start, so a
level costs one to three factorisations.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from scipy import sparse
from scipy.sparse.linalg import LinearOperator, onenormest, splu

from formulations.base import STATUS_FAILED, STATUS_OK, ContactQP, SolverDiagnostics
from formulations.solvers.backends import factorise
from formulations.solvers.lcp import SINGULAR
from formulations.solvers.stopping import FIXED_STOPPING, QPLinearisation, Stopping

VIOLATION_TOLERANCE = 1e-12  # relative to the displacement scale: round-off, not penetration


def initial_active_set(qp: ContactQP, backend: str = "splu") -> np.ndarray:
    """{i : (B u0 - G)_i > 0} for the unconstrained u0 = K^-1 F (u0 = 0 when F = 0)."""
    if not np.any(qp.F):
        return -qp.G > 0
    return qp.B @ factorise(qp.K, backend, qp.near_null)(qp.F) - qp.G > 0


def condition_estimate(system: sparse.csc_matrix, lu) -> float:
    """1-norm condition estimate ||A||_1 ||A^-1||_1 of a factorised matrix (Higham's block
    estimator for the inverse: a few solves, never the inverse itself). Its random test
    vectors come from numpy's global generator, seeded here and restored after, so that a
    rerun gives the same number."""
    n = system.shape[0]
    inverse = LinearOperator((n, n), matvec=lu.solve, rmatvec=lambda x: lu.solve(x, trans="T"),
                             dtype=float)
    state = np.random.get_state()
    np.random.seed(0)
    try:
        norm = onenormest(inverse)
    finally:
        np.random.set_state(state)
    return float(abs(system).sum(axis=0).max() * norm)


def solve_augmented(qp: ContactQP, active: np.ndarray, max_iter: int,
                    stopping: Stopping = FIXED_STOPPING):
    """Returns (u, lambda, iterations, status, reason, diagnostics): the diagnostics hold the
    active-set changes of every iteration, whether a set repeated (``cycled``) and the
    condition estimate of the last (scaled) saddle-point matrix factorised. An adaptive
    ``stopping`` ends the iteration at the first iterate whose eta_lin meets its criterion
    (each solve is direct: no algebraic part; docs/theory.md, 18.3)."""
    n, m = qp.n, qp.m
    # scaled like the reference: K / E, rows of B / row_scale (an O(1) saddle-point matrix)
    K = sparse.csr_matrix(qp.K) / qp.objective_scale
    B = sparse.diags(1.0 / qp.row_scale) @ qp.B
    G = qp.G / qp.row_scale
    F = qp.F / qp.objective_scale
    seen, changes = set(), []
    u, lam = np.zeros(n), np.zeros(m)
    linearisation = QPLinearisation(qp.K, qp.B, qp.G)

    def diagnostics(cycled, system=None, lu=None):
        return SolverDiagnostics(
            active_set_changes=tuple(changes), cycled=cycled,
            condition_estimate=condition_estimate(system, lu) if lu is not None
            else float("nan"))

    for iteration in range(1, max_iter + 1):
        key = active.tobytes()
        if key in seen:
            return (u, lam, iteration - 1, STATUS_FAILED, "active set cycles (a set repeated)",
                    diagnostics(True))
        seen.add(key)
        rows = np.flatnonzero(active)
        B_A = B[rows]
        system = sparse.bmat([[K, B_A.T], [B_A, None]], format="csc")
        rhs = np.concatenate([F, G[rows]])
        try:
            lu = splu(system)
        except RuntimeError:  # "Factor is exactly singular": dependent active rows of B
            return u, lam, iteration, STATUS_FAILED, SINGULAR, diagnostics(False)
        solution = lu.solve(rhs)
        solution += lu.solve(rhs - system @ solution)  # one step of iterative refinement
        u, lam = solution[:n], np.zeros(m)
        lam[rows] = solution[n:] * qp.objective_scale / qp.row_scale[rows]
        slack = qp.G - qp.B @ u
        scale = max(np.abs(u).max(initial=0.0), qp.gap_scale, np.finfo(float).tiny)
        new_active = np.where(active, lam > 0, slack < -VIOLATION_TOLERANCE * scale)
        changes.append(int((new_active != active).sum()))
        if changes[-1] == 0:
            return u, lam, iteration, STATUS_OK, "", diagnostics(False, system, lu)
        if stopping.adaptive and stopping.newton_done(
                linearisation(u, lam, stopping.load_norm)):
            return (u, lam, iteration, STATUS_OK, "",
                    replace(diagnostics(False, system, lu), stopped_early=True))
        active = new_active
    return (u, lam, max_iter, STATUS_FAILED,
            f"active set still changing after {max_iter} iterations", diagnostics(False))

"""Bound-constrained least squares, argmin_{x >= 0} ||A x - b||^2 + ||w x||^2, by Clarabel's
interior-point method on the sparse normal equations, then active-set steps to the exact
minimiser (docs/theory.md, 13.3): the non-negative pressures that
reproduce nodal reactions (``formulations.contact.surface_nodes`` for vi's P2 pressure on a 3D
contact surface, ``estimators.guaranteed.nonnegative_traction`` for the guaranteed bound's
lambda*)."""

from __future__ import annotations

import clarabel
import numpy as np
from scipy import sparse
from scipy.sparse.linalg import spsolve

TOLERANCE = 1e-12  # the problems are small and well scaled: solved to round-off
# entries above this share of the largest are the positive set of ``polished``: the interior
# point leaves its zeros at about TOLERANCE times the scale
POSITIVE = 1e-6
GRADIENT = 1e-12  # a fixed entry joins the free ones where its gradient is below -this |A'b|
POLISH_STEPS = 30  # active-set steps of ``polished``: measured 1 .. 5 (paper, hertz, 2D and 3D)


def bounded_least_squares(A: sparse.spmatrix, b: np.ndarray, weights: np.ndarray
                          ) -> np.ndarray | None:
    """x >= 0 minimising ||A x - b||^2 + ||weights * x||^2, or None if Clarabel does not
    solve it (the caller then keeps its fallback)."""
    n = A.shape[1]
    P = sparse.triu(2 * (A.T @ A + sparse.diags(weights**2))).tocsc()
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    settings.tol_gap_abs = settings.tol_gap_rel = settings.tol_feas = TOLERANCE
    solver = clarabel.DefaultSolver(P, -2 * (A.T @ b), -sparse.eye(n, format="csc"),
                                    np.zeros(n), [clarabel.NonnegativeConeT(n)], settings)
    solution = solver.solve()
    if solution.status not in (clarabel.SolverStatus.Solved, clarabel.SolverStatus.AlmostSolved):
        return None
    return polished(A, b, weights, np.maximum(np.asarray(solution.x), 0.0))


def polished(A: sparse.spmatrix, b: np.ndarray, weights: np.ndarray, x: np.ndarray
             ) -> np.ndarray:
    """The exact minimiser from the interior point's answer x: primal-dual active-set steps
    on the normal equations N x = A'b (N = A'A + diag(weights^2)), started from x's positive
    entries, until the sets repeat (then the KKT conditions hold to round-off); the best
    feasible iterate, or x, if they do not settle within POLISH_STEPS.

    With small weights the minimiser is weakly determined and the interior point stops short
    of it along the near-null directions of A: on `paper`, vi, P3, 3072 elements, its answer
    was 0.6 % from the minimiser, whose objective is lower, and a change of 3e-14 in b (the
    thread count's round-off in u) moved it by 3e-6 relative and the guaranteed bound by
    1.4e-5. The minimiser moves by about the conditioning times the change."""
    A = sparse.csc_matrix(A)
    normal, right = (A.T @ A + sparse.diags(weights**2)).tocsc(), A.T @ b
    best, least = x, objective(A, b, weights, x)
    free = x > POSITIVE * x.max(initial=0.0)
    tolerance = GRADIENT * np.abs(right).max(initial=0.0)
    for _ in range(POLISH_STEPS):
        candidate = np.zeros_like(x)
        if free.any():
            candidate[free] = spsolve(normal[free][:, free], right[free])
        gradient = normal @ candidate - right
        if candidate.min(initial=0.0) >= 0 and objective(A, b, weights, candidate) <= least:
            best, least = candidate, objective(A, b, weights, candidate)
        new_free = np.where(free, candidate > 0, gradient < -tolerance)
        if np.array_equal(new_free, free):
            return best
        free = new_free
    return best


def objective(A: sparse.spmatrix, b: np.ndarray, weights: np.ndarray, x: np.ndarray) -> float:
    return float(np.sum((A @ x - b) ** 2) + np.sum((weights * x) ** 2))

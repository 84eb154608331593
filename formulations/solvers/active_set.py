"""``active-set``: primal-dual active set method on the condensed contact system.

For min 1/2 u'Ku - F'u s.t. Bu <= G with K symmetric positive definite, u = u0 - K^-1 B' lambda
with u0 = K^-1 F, so the KKT conditions reduce to a linear complementarity problem in the few
contact unknowns (they live on one boundary line):

    y = S lambda - r >= 0,  lambda >= 0,  lambda' y = 0,   S = B K^-1 B',  r = B u0 - G,

where y = G - Bu is the slack. K is factorised once, and S comes from the same factorisation
through the Schur complement of K on the contact DOFs (``backends``); nothing is refactorised
between iterations. The LCP is solved by the primal-dual active set method (Hintermueller, Ito,
Kunisch 2003; a semismooth Newton method):

    A = {i : lambda_i - c y_i > 0};  lambda_I = 0,  S_AA lambda_A = r_A;  repeat until A is fixed.

At termination lambda_A >= 0 and y_I >= 0 hold exactly (up to round-off), so the answer is exact.
A repeated active set (cycling) or the iteration limit stops it with status ``failed`` and the
reason. The first active set is {i : r_i > 0} (the constraints the unconstrained solution
violates) unless ``warm_start`` multipliers are given: then it is {i : warm_start_i > 0}, which is
how the refinement loop's nested iteration passes the previous level's contact zone.
"""

from __future__ import annotations

import time

import numpy as np
from scipy import linalg

from formulations.base import STATUS_FAILED, STATUS_OK, ContactQP, QPSolution
from formulations.solvers.augmented import initial_active_set, solve_augmented
from formulations.solvers.backends import check_backend, factorise_condensed
from formulations.solvers.registry import register_solver


def pdas(S: np.ndarray, r: np.ndarray, active: np.ndarray, max_iter: int):
    """Solve the LCP y = S lam - r >= 0, lam >= 0, lam'y = 0 by primal-dual active sets.

    Returns (lam, iterations, status, reason)."""
    m = r.size
    c = 1.0 / max(float(np.mean(np.diag(S))), np.finfo(float).tiny) if m else 1.0
    seen = set()
    lam = np.zeros(m)
    for iteration in range(1, max_iter + 1):
        key = active.tobytes()
        if key in seen:
            return lam, iteration - 1, STATUS_FAILED, "active set cycles (a set repeated)"
        seen.add(key)
        lam = np.zeros(m)
        if active.any():
            lam[active] = linalg.solve(S[np.ix_(active, active)], r[active], assume_a="pos")
        y = S @ lam - r
        new_active = lam - c * y > 0
        if np.array_equal(new_active, active):
            return lam, iteration, STATUS_OK, ""
        active = new_active
    return lam, max_iter, STATUS_FAILED, f"active set still changing after {max_iter} iterations"


@register_solver("active-set", "primal-dual active set (semismooth Newton): condensed "
                               "B K^-1 B' from one factorisation (cholmod) or the augmented "
                               "saddle-point system (splu); nested iteration")
def solve_active_set(qp: ContactQP, warm_start: np.ndarray | None = None,
                     max_iter: int = 100, backend: str | None = None) -> QPSolution:
    """``backend``: 'cholmod' (condensed iteration) or 'splu' (augmented iteration, see
    ``augmented``); default: the fastest available, see ``backends``."""
    start = time.perf_counter()
    backend = check_backend(backend)
    if warm_start is not None and np.shape(warm_start) != (qp.m,):
        raise ValueError(f"warm_start has shape {np.shape(warm_start)}, not ({qp.m},)")
    if backend == "splu":
        active = (np.asarray(warm_start) > 0) if warm_start is not None else \
            initial_active_set(qp)
        u, lam, iterations, status, reason = solve_augmented(qp, active, max_iter)
        return QPSolution(u=u, multipliers=lam, status=status, reason=reason,
                          iterations=iterations, solve_time=time.perf_counter() - start,
                          solver="active-set", backend="splu")
    factor = factorise_condensed(qp.K, np.unique(qp.B.indices), backend)
    u0 = factor.solve(qp.F)
    S = factor.condensed(qp.B)
    r = qp.B @ u0 - qp.G
    active = (np.asarray(warm_start) > 0) if warm_start is not None else (r > 0)
    lam, iterations, status, reason = pdas(S, r, active, max_iter)
    u = factor.solve(qp.F - qp.B.T @ lam)
    return QPSolution(u=u, multipliers=lam, status=status, reason=reason, iterations=iterations,
                      solve_time=time.perf_counter() - start, solver="active-set",
                      backend=factor.backend)

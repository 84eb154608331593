"""Dense linear complementarity problems y = S lam - r >= 0, lam >= 0, lam'y = 0 with S
symmetric positive definite (the condensed contact system B K^-1 B', see ``active_set``).

* ``pdas``: the primal-dual active set method (Hintermueller, Ito, Kunisch 2003; the semismooth
  Newton method on lam = max(0, lam - c y)). Fast -- a handful of iterations, and 1-3 with
  nested iteration -- but not globally convergent for every SPD S: it can cycle (a random
  search over 3x3..5x5 SPD matrices finds such cases; ``CYCLING_EXAMPLE`` keeps one; Ben
  Gharbia and Gilbert 2012 show it for P-matrices in general).
* ``least_index_pivoting``: Murty's principal pivoting with the least-index rule (Murty 1974):
  flip only the smallest infeasible index of the current complementary basis. It terminates
  in finitely many steps for every P-matrix, so it is the safeguard the active-set solver
  switches to when ``pdas`` cycles; it may need many more (cheap, dense) steps.

Both record the number of active-set changes of every iteration (the solver's diagnostics).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import linalg

from formulations.base import STATUS_FAILED, STATUS_OK

# a multiplier or slack counts as negative below -ROUNDOFF x its natural scale: without it the
# pivoting rule chases the signs of round-off on degenerate (grazing) problems
ROUNDOFF = 1e-12


# (S, r, initial active set) on which plain PDAS cycles: found by a random search over SPD
# matrices (numpy seed 0, trial 2392); from this start it revisits an active set after 5 steps
CYCLING_EXAMPLE = (
    np.array([[3.33914076, -1.96172517, -0.00715703, -1.06847366, 1.66118594],
              [-1.96172517, 3.25846728, 0.04343212, -0.39452142, -1.75831306],
              [-0.00715703, 0.04343212, 6.52869201, -1.95694266, -1.46103878],
              [-1.06847366, -0.39452142, -1.95694266, 2.59830682, 1.04405007],
              [1.66118594, -1.75831306, -1.46103878, 1.04405007, 1.9634999]]),
    np.array([0.02812848, -2.17454055, 1.15602742, -0.07672046, 0.86086229]),
    np.array([False, True, False, True, False]))


@dataclass(frozen=True)
class LCPResult:
    lam: np.ndarray
    iterations: int
    status: str
    reason: str
    changes: tuple[int, ...]  # active-set changes of each iteration (0 at convergence)
    cycled: bool
    active: np.ndarray


SINGULAR = ("singular active block S_AA: the active rows of B are linearly dependent (the "
            "multipliers are not unique)")


class SingularActiveBlock(Exception):
    """S_AA is singular: a multiplier space that is not inf-sup stable (B' has a kernel)."""


def _solve_active(S, r, active):
    lam = np.zeros(r.size)
    if active.any():
        try:
            lam[active] = linalg.solve(S[np.ix_(active, active)], r[active], assume_a="pos")
        except linalg.LinAlgError as error:
            raise SingularActiveBlock(SINGULAR) from error
    return lam, S @ lam - r


def pdas(S: np.ndarray, r: np.ndarray, active: np.ndarray, max_iter: int,
         settled=None) -> LCPResult:
    """Primal-dual active sets from the initial ``active`` set; ``settled(lam, y)`` (optional,
    a stopping rule's) ends the iteration at an iterate whose set still changes."""
    m = r.size
    c = 1.0 / max(float(np.mean(np.diag(S))), np.finfo(float).tiny) if m else 1.0
    seen, changes = set(), []
    lam = np.zeros(m)
    for iteration in range(1, max_iter + 1):
        key = active.tobytes()
        if key in seen:
            return LCPResult(lam, iteration - 1, STATUS_FAILED,
                             "active set cycles (a set repeated)", tuple(changes), True, active)
        seen.add(key)
        try:
            lam, y = _solve_active(S, r, active)
        except SingularActiveBlock:
            return LCPResult(lam, iteration, STATUS_FAILED, SINGULAR, tuple(changes), False,
                             active)
        new_active = lam - c * y > 0
        changes.append(int((new_active != active).sum()))
        if changes[-1] == 0 or (settled is not None and settled(lam, y)):
            return LCPResult(lam, iteration, STATUS_OK, "", tuple(changes), False, active)
        active = new_active
    return LCPResult(lam, max_iter, STATUS_FAILED,
                     f"active set still changing after {max_iter} iterations", tuple(changes),
                     False, active)


def least_index_pivoting(S: np.ndarray, r: np.ndarray, active: np.ndarray,
                         max_iter: int) -> LCPResult:
    """Murty's least-index principal pivoting from ``active``: finite for SPD ``S``."""
    changes = []
    lam = np.zeros(r.size)
    active = active.copy()
    for iteration in range(1, max_iter + 1):
        try:
            lam, y = _solve_active(S, r, active)
        except SingularActiveBlock:
            return LCPResult(lam, iteration, STATUS_FAILED, SINGULAR, tuple(changes), False,
                             active)
        lam_tol = ROUNDOFF * max(np.abs(lam).max(initial=0.0), np.finfo(float).tiny)
        y_tol = ROUNDOFF * max(np.abs(r).max(initial=0.0), np.finfo(float).tiny)
        infeasible = np.flatnonzero(np.where(active, lam < -lam_tol, y < -y_tol))
        if infeasible.size == 0:
            changes.append(0)
            lam[~active] = 0.0
            return LCPResult(np.maximum(lam, 0.0), iteration, STATUS_OK, "", tuple(changes),
                             False, active)
        active[infeasible[0]] = ~active[infeasible[0]]
        changes.append(1)
    return LCPResult(lam, max_iter, STATUS_FAILED,
                     f"least-index pivoting still changing after {max_iter} iterations",
                     tuple(changes), False, active)


def condition_1(S: np.ndarray, active: np.ndarray) -> float:
    """1-norm condition number of the active block S_AA (NaN when nothing is active)."""
    if not active.any():
        return float("nan")
    return float(np.linalg.cond(S[np.ix_(active, active)], 1))

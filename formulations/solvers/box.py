"""Dense box-constrained QPs min 1/2 lam'S lam - r'lam s.t. lower <= lam <= upper, S SPD: the
condensed Tresca problem (docs/theory.md, 17.3), normal reactions in [0, inf) and tangential
ones in [-b, b].

``box_pdas`` is the primal-dual active set method for box constraints (Hintermueller, Ito,
Kunisch 2003): with the slack y = r - S lam (the normal gap Bu - G, the tangential slip Tu)
and c = 1 / mean diag S,

    lam_i = lower_i where lam_i + c y_i < lower_i,  lam_i = upper_i where it is > upper_i,
    y_i = 0 elsewhere,

one SPD solve on the free block per iteration, until the sets reproduce themselves: the answer
is then exact (the sign conditions hold by construction). A node whose bounds coincide (a
Coulomb node out of contact, bound 0) is fixed from the start.

The iteration is not globally convergent: from a poor start it can cycle. ``box_bvls`` is the
safeguard: with S = L L' the box QP is the bounded least-squares problem
min ||L' lam - L^-1 r||^2 / 2, which the Stark-Parker BVLS active set method solves in finitely
many steps (scipy's ``lsq_linear``); its sets then start ``box_pdas``, which confirms them in
one iteration where they are right and leaves an exact answer.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import linalg
from scipy.optimize import lsq_linear

from formulations.base import STATUS_FAILED, STATUS_OK
from formulations.solvers.lcp import SINGULAR

AT_LOWER, FREE, AT_UPPER = -1, 0, 1


@dataclass(frozen=True)
class BoxResult:
    lam: np.ndarray
    state: np.ndarray | None  # AT_LOWER, FREE or AT_UPPER per entry (None: discs, no sets)
    iterations: int
    status: str
    reason: str
    changes: tuple[int, ...]
    cycled: bool
    safeguard: str = ""  # what answered instead of the plain iteration ("" if nothing did)


def initial_state(r: np.ndarray, lower: np.ndarray, upper: np.ndarray) -> np.ndarray:
    """The state of lam = 0: entries whose unconstrained pull r leaves the box are at that
    bound (normal rows the unconstrained solution violates are free, i.e. in contact)."""
    state = np.where(r < lower, AT_LOWER, np.where(r > upper, AT_UPPER, FREE))
    return np.where(lower == upper, AT_LOWER, state)


def _solve_free(S, r, lower, upper, state):
    lam = np.where(state == AT_LOWER, lower, np.where(state == AT_UPPER, upper, 0.0))
    free = state == FREE
    if free.any():
        fixed = ~free
        rhs = r[free] - S[np.ix_(free, fixed)] @ lam[fixed]
        try:
            lam[free] = linalg.solve(S[np.ix_(free, free)], rhs, assume_a="pos")
        except linalg.LinAlgError as error:
            raise ValueError(SINGULAR) from error
    return lam, r - S @ lam


def box_pdas(S: np.ndarray, r: np.ndarray, lower: np.ndarray, upper: np.ndarray,
             state: np.ndarray, max_iter: int = 100) -> BoxResult:
    """Primal-dual active sets for the box QP from ``state``; ``upper`` may be inf."""
    c = 1.0 / max(float(np.mean(np.diag(S))), np.finfo(float).tiny) if r.size else 1.0
    pinned = lower == upper
    state = np.where(pinned, AT_LOWER, state)
    seen, changes = set(), []
    lam = np.zeros(r.size)
    for iteration in range(1, max_iter + 1):
        key = state.tobytes()
        if key in seen:
            return BoxResult(lam, state, iteration - 1, STATUS_FAILED,
                             "active set cycles (a set repeated)", tuple(changes), True)
        seen.add(key)
        try:
            lam, y = _solve_free(S, r, lower, upper, state)
        except ValueError as error:
            return BoxResult(lam, state, iteration, STATUS_FAILED, str(error), tuple(changes),
                             False)
        trial = lam + c * y
        new = np.where(trial < lower, AT_LOWER, np.where(trial > upper, AT_UPPER, FREE))
        new = np.where(pinned, AT_LOWER, new)
        changes.append(int((new != state).sum()))
        if changes[-1] == 0:
            return BoxResult(lam, state, iteration, STATUS_OK, "", tuple(changes), False)
        state = new
    return BoxResult(lam, state, max_iter, STATUS_FAILED,
                     f"active set still changing after {max_iter} iterations", tuple(changes),
                     False)


def box_bvls(S: np.ndarray, r: np.ndarray, lower: np.ndarray, upper: np.ndarray,
             max_iter: int = 100) -> BoxResult:
    """The box QP by bounded least squares (module docstring), then confirmed by
    ``box_pdas`` from the sets it found."""
    pinned = lower == upper
    movable = ~pinned
    lam = np.where(pinned, lower, 0.0)
    if movable.any():
        block = S[np.ix_(movable, movable)]
        rhs = r[movable] - S[np.ix_(movable, pinned)] @ lam[pinned]
        try:
            factor = linalg.cholesky(block, lower=True)
        except linalg.LinAlgError:
            return BoxResult(lam, initial_state(r, lower, upper), 0, STATUS_FAILED, SINGULAR,
                             (), False)
        target = linalg.solve_triangular(factor, rhs, lower=True)
        fit = lsq_linear(factor.T, target, bounds=(lower[movable], upper[movable]),
                         method="bvls", max_iter=max(max_iter, 10 * r.size))
        lam[movable] = fit.x
    span = np.maximum(np.abs(upper - lower), 1.0)
    near = 1e-12 * np.where(np.isfinite(span), span, np.abs(lam).max(initial=1.0))
    state = np.where(lam <= lower + near, AT_LOWER,
                     np.where(lam >= upper - near, AT_UPPER, FREE))
    result = box_pdas(S, r, lower, upper, state, max_iter)
    return BoxResult(result.lam, result.state, result.iterations, result.status,
                     result.reason and f"after bounded least squares: {result.reason}",
                     result.changes, result.cycled, safeguard="bounded least squares")

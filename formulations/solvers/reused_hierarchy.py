"""Newton steps on an iterative back-end that reuse the last multigrid hierarchy (docs/theory.md,
sections 12.3 and 16).

On the sparse route two Jacobians K + T' D_A T differ by one rank-one term per contact point
whose state changed, so the smoothed-aggregation hierarchy built for one preconditions the
next almost as well, and building it is most of a step's cost: on hertz-3d at 52 272 P1 DOFs,
Nitsche (theta = 1) spent 2.61 of its 3.56 s in five hierarchy set-ups.

A step therefore solves its own Jacobian by CG preconditioned with the held hierarchy, within a
budget: BUDGET of the iterations that cost as much as a new hierarchy (its set-up, timed on this
machine, plus the iterations the held hierarchy needed for its own matrix, scaled to the digits
asked; at least MIN_BUDGET). It builds a new hierarchy instead

- when more than CHANGED_PER_ITERATION contact points per budgeted iteration changed since the
  held hierarchy's Jacobian (each adds a rank-one term, and CG pays for them);
- when the last reused step's iterations per digit predict more than the budget;
- when CG has not reached the tolerance within the budget, and, after GIVE_UP such failures in
  a row, at every later step of the same solve (the penalty's stiff terms, 1/eps on each
  changed point, defeat a float32 V-cycle of an earlier Jacobian: on `paper` P2 at 33 024 DOFs
  reuse failed at 11 of 16 steps, with 5 .. 67 points changed, while Nitsche's converged);
- when the Jacobian is not symmetric (GMRES; Nitsche with theta != 1).

Either way the step is a solve to the requested tolerance, never an inexact one; which route
gave it changes u by the solver's tolerance only.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
from scipy import sparse

from formulations.solvers.backends import FactorisationError, factorise
from formulations.solvers.backends.amg import RTOL

BUDGET = 0.7     # the share of a new hierarchy's cost that a reused step may spend
MIN_BUDGET = 5   # a floor for the budget (timings of tiny solves are noise)
# changed points per budgeted iteration above which a step builds a new hierarchy at once: on
# the adaptive hertz-3d penalty and Nitsche sequences to 6e4 DOFs, reuse converged for every
# step with up to 83 changed points and failed for every one with 323 or more (budgets ~45)
CHANGED_PER_ITERATION = 5
GIVE_UP = 2  # failed attempts in a row after which a solve builds every step's hierarchy


@dataclass(eq=False)
class ReusedHierarchy:
    """Solves J dx = rhs for successive Jacobians J on the iterative back-end ``backend``;
    ``setups`` counts the hierarchies built, ``iterations`` every solve's Krylov count."""

    backend: str
    near_null: np.ndarray | None
    held: object = None
    own_iterations: int = 0
    own_rtol: float = RTOL
    setup_iterations: float = 0.0  # a set-up's time in iterations of the held hierarchy
    reused_per_digit: float = 0.0  # iterations per digit of the last reused step
    setups: int = 0
    held_active: np.ndarray | None = None
    changed: int = -1
    failures: int = 0  # attempts in a row that ran out of budget
    iterations: list[int] = field(default_factory=list)
    by_rule: bool = False  # a stopping rule ended the last solve

    def __call__(self, J: sparse.spmatrix, rhs: np.ndarray, rtol: float | None,
                 active: np.ndarray | None = None, done=None) -> np.ndarray:
        self.changed = (-1 if active is None or self.held_active is None
                        or active.shape != self.held_active.shape
                        else int(np.count_nonzero(active != self.held_active)))
        digits = -np.log10(rtol or RTOL)
        if self.held is not None and hasattr(self.held, "for_matrix"):
            budget = max(MIN_BUDGET, int(BUDGET * (self.setup_iterations + self.own_iterations
                                                   * digits / -np.log10(self.own_rtol))))
            if (self.failures < GIVE_UP and self.reused_per_digit * digits <= budget
                    and self.changed <= CHANGED_PER_ITERATION * budget):
                reused = self.held.for_matrix(J, budget)
                dx = self._attempt(reused, rhs, rtol, done)
                if reused.symmetric and reused.iterations:
                    self.reused_per_digit = reused.iterations[-1] / digits
                if dx is not None:
                    self.failures = 0
                    self.by_rule = bool(reused.by_rule and reused.by_rule[-1])
                    return dx
                self.failures += reused.symmetric
        start = time.perf_counter()
        self.held = factorise(J, self.backend, self.near_null)
        self.held_active = None if active is None else np.array(active, copy=True)
        built = time.perf_counter()
        self.setups += 1
        dx = self.held(rhs, rtol=rtol, done=done)
        self.by_rule = bool(self.held.by_rule and self.held.by_rule[-1])
        self.own_iterations = self.held.iterations[-1] if self.held.iterations else 0
        per_iteration = (time.perf_counter() - built) / max(self.own_iterations, 1)
        self.setup_iterations = (built - start) / max(per_iteration, 1e-9)
        self.reused_per_digit = 0.0
        self.own_rtol = rtol or RTOL
        self.iterations.extend(self.held.iterations)
        return dx

    def _attempt(self, reused, rhs: np.ndarray, rtol: float | None,
                 done=None) -> np.ndarray | None:
        """The reused hierarchy's answer, or None (not symmetric, or over budget)."""
        if not reused.symmetric:
            return None
        try:
            return reused(rhs, rtol=rtol, done=done)
        except FactorisationError:
            return None
        finally:
            self.iterations.extend(reused.iterations)

"""Sparse Newton steps that reuse the last factorised Jacobian (docs/theory.md, section 12.3).

On the sparse route the Jacobian of the active set A is J_A = K + T' D_A T with D_A diagonal
over the quadrature points, so two Jacobians differ by one rank-one term per point whose state
changed. Conjugate gradients on J_A preconditioned by an earlier factorisation J_0^-1 then see
the identity plus a perturbation of rank k (the points that changed since J_0) and converge in
at most k + 1 iterations, each one back-substitution: 0.02 s against 1.25 s for a factorisation
at 52 272 P1 DOFs (hertz-3d, nitsche, pardiso). Both matrices must be SPD, which is when the
route takes sparse steps on a direct back-end (a penalty; theta = 1).

In practice CG needs far fewer iterations than k, because the rank-one terms of one contact
zone are alike: 8 .. 13 for k = 25 .. 56 and 24 .. 64 for k = 160 .. 270 on the adaptive
hertz-3d levels of 5e3 .. 5.7e4 DOFs (k / 6 .. k / 3). So a step tries CG, with a budget of as
many iterations as cost BUDGET of a factorisation (timed on this machine, on the factorisation
and its first back-substitution), when k is at most CHANGED_PER_ITERATION times that budget;
it factorises its own Jacobian otherwise, or when CG has not reached RTOL within the budget (or
within k + 1 + SLACK iterations). The answer is always a solve to RTOL, never an
inexact one; which of the two routes gave it changes u by round-off only.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from scipy import sparse

from formulations.solvers.backends import factorise

# the share of a factorisation's time that a reused step may spend on CG before it gives up
BUDGET = 0.7
# relative residual |b - J x| / |b| of a reused step: the round-off of a direct solve's
# residual on these Jacobians is 1e-15 .. 1e-13
RTOL = 1e-13
SLACK = 10  # iterations beyond k + 1 that round-off may take
# changed points per CG iteration below which a step tries CG: on the adaptive hertz-3d
# penalty levels it converged where k was 1.8 .. 4.6 budgets and gave up from 5.7 budgets up
# (each attempt that gives up costs BUDGET of a factorisation)
CHANGED_PER_ITERATION = 5


def preconditioned_cg(J: sparse.csr_matrix, b: np.ndarray, precondition: Callable,
                      max_iterations: int) -> tuple[np.ndarray | None, int]:
    """(x, iterations) with |b - J x| <= RTOL |b|, or (None, iterations) if CG did not get
    there within ``max_iterations``."""
    x = precondition(b)
    r = b - J @ x
    norm = np.linalg.norm(b)
    z = precondition(r)
    p, rz = z.copy(), r @ z
    for iteration in range(max_iterations + 1):
        if np.linalg.norm(r) <= RTOL * norm:
            return x, iteration
        Jp = J @ p
        alpha = rz / (p @ Jp)
        x, r = x + alpha * p, r - alpha * Jp
        z = precondition(r)
        rz, rz_old = r @ z, rz
        p = z + (rz / rz_old) * p
    return None, max_iterations


@dataclass(eq=False)
class ReusedFactorisation:
    """J_A^-1 b for the Jacobians of one Newton iteration on a direct back-end (module
    docstring); ``factorisations`` and ``iterations`` (CG's, per reused step) are counted."""

    backend: str
    solve_0: Callable | None = None
    active_0: np.ndarray | None = None
    budget: int = 0  # CG iterations that cost BUDGET of the last factorisation
    factorisations: int = 0
    iterations: list[int] = field(default_factory=list)

    def __call__(self, J: sparse.csr_matrix, active: np.ndarray, b: np.ndarray) -> np.ndarray:
        changed = 0 if self.active_0 is None else int((active != self.active_0).sum())
        if self.solve_0 is not None and changed <= CHANGED_PER_ITERATION * self.budget:
            limit = min(changed + 1 + SLACK, self.budget)
            x, count = preconditioned_cg(J, b, self.solve_0, limit)
            self.iterations.append(count)
            if x is not None:
                return x
        clock = time.perf_counter()
        self.solve_0, self.active_0 = factorise(J, self.backend), np.array(active)
        factorised = time.perf_counter()
        x = self.solve_0(b)
        # a CG iteration: one back-substitution and one product with J (about a third of it)
        iteration = 4 / 3 * (time.perf_counter() - factorised)
        self.budget = int(BUDGET * (factorised - clock) / max(iteration, 1e-9))
        self.factorisations += 1
        return x

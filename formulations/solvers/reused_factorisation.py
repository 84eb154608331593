"""Sparse Newton steps that reuse the last factorised Jacobian (docs/theory.md, section 12.3).

On the sparse route the Jacobian of the active set A is J_A = K + T' D_A T with D_A diagonal
over the quadrature points, so two Jacobians differ by one rank-one term per point whose state
changed. Conjugate gradients on J_A preconditioned by an earlier factorisation J_0^-1 then see
the identity plus a perturbation of rank k (the points that changed since J_0) and converge in
at most k + 1 iterations, each one back-substitution: 0.02 s against 1.25 s for a factorisation
at 52 272 P1 DOFs (hertz-3d, nitsche, pardiso). Both matrices must be SPD, which is when the
route takes sparse steps on a direct back-end (a penalty; theta = 1).

A step factorises its own Jacobian when more than REUSE_UP_TO points changed since the last
factorisation, or when CG has not reached RTOL after k + SLACK iterations: the answer is always
a solve to RTOL, never an inexact one.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from scipy import sparse

from formulations.solvers.backends import factorise

# changed points beyond which a new factorisation is cheaper than k + 1 back-substitutions
# (plus a product with J each): 40 x 0.03 s against 1.25 s at 52 272 DOFs
REUSE_UP_TO = 40
# relative residual |b - J x| / |b| of a reused step: the round-off of a direct solve's
# residual on these Jacobians is 1e-15 .. 1e-13
RTOL = 1e-13
SLACK = 10  # iterations beyond k + 1 that round-off may take


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
    factorisations: int = 0
    iterations: list[int] = field(default_factory=list)

    def __call__(self, J: sparse.csr_matrix, active: np.ndarray, b: np.ndarray) -> np.ndarray:
        if self.solve_0 is not None:
            changed = int((active != self.active_0).sum())
            if changed <= REUSE_UP_TO:
                x, count = preconditioned_cg(J, b, self.solve_0, changed + 1 + SLACK)
                self.iterations.append(count)
                if x is not None:
                    return x
        self.solve_0, self.active_0 = factorise(J, self.backend), np.array(active)
        self.factorisations += 1
        return self.solve_0(b)

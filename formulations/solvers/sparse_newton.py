"""Semismooth Newton steps on u with the full sparse Jacobian K + T' D_A T (docs/theory.md,
12.3): SuperLU, a direct back-end's reused factorisation, or CG / GMRES on an iterative
back-end; under an adaptive stopping rule its CG solves and its iteration stop by the rule
(docs/theory.md, 18.3)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import sparse
from scipy.sparse.linalg import splu

from formulations.semismooth import SemismoothSystem
from formulations.solvers.backends import iterative
from formulations.solvers.newton import Linearised
from formulations.solvers.reused_factorisation import ReusedFactorisation
from formulations.solvers.reused_hierarchy import ReusedHierarchy
from formulations.solvers.stopping import FIXED_STOPPING, Stopping

# an iterative back-end's relative residual while the active set changes. paper-3d P1,
# V-cycles in all with 1e-4 / 1e-3, the same u: penalty 120 / 123 at 13 872 DOFs and
# 561 / 290 at 104 544, nitsche 115 / 94 and 207 / 189
SEARCH_RTOL = 1e-3


def sparse_problem(system: SemismoothSystem, backend: str | None = None,
                   stopping: Stopping = FIXED_STOPPING) -> Linearised:
    """Newton on u with the full sparse Jacobian K + T' D_A T, factorised once a step: by the
    back-end ``backend`` (an SPD Jacobian: a system without S; or an iterative back-end,
    which takes any Jacobian), else by SuperLU. An iterative back-end's Krylov iterations of
    every step are appended to ``krylov``; under an adaptive ``stopping`` its CG solves end
    by the rule's eta_alg criterion and the iteration by its eta_lin one (``AdaptiveSteps``)."""
    T = system.T
    krylov: list[int] = []
    direct = ReusedFactorisation(backend) if backend is not None else None
    hierarchy = ReusedHierarchy(backend, system.near_null) if iterative(backend) else None
    steps = AdaptiveSteps(system, stopping)
    # an iterative back-end's relative residual, per step; under an adaptive rule the rule
    # ends every solve (RTOL a floor)
    rtol = [None if steps.stopping.adaptive else SEARCH_RTOL if iterative(backend) else 0.0]

    def tighten() -> bool:
        """Solve to the back-end's own tolerance from now on; True if it was looser and the
        stopping rule did not end the last solve."""
        looser, rtol[0] = rtol[0] == SEARCH_RTOL and not steps.by_rule, None
        return looser

    def step(active, u):
        J = system_matrix(system, active)
        rhs = -(J @ u + T.T @ system.phi_affine(active)[1] - system.F)
        if backend is not None and iterative(backend):
            if not np.any(system.F - T.T @ system.phi_affine(active)[1]):
                return -u, float("nan")  # no load, no contact: u = 0 exactly, not round-off
            done = len(hierarchy.iterations)
            dx = hierarchy(J, rhs, rtol[0], active, steps.krylov_rule(u))
            krylov.extend(hierarchy.iterations[done:])
            steps.record(J @ dx - rhs, hierarchy.by_rule)
            return dx, float("nan")
        steps.record(np.zeros_like(rhs), True)  # a direct solve: no algebraic residual
        if direct is not None:  # SPD: reuse an earlier factorisation (reused_factorisation)
            return direct(J, active, rhs), float("nan")
        return splu(J.tocsc()).solve(rhs), float("nan")

    return Linearised(system.residual, lambda u: system.pressure_argument(T @ u), step,
                      lambda u: np.linalg.norm(system.F) + np.linalg.norm(system.K @ u),
                      krylov, tighten, steps.settled, steps)


@dataclass(eq=False)
class AdaptiveSteps:
    """The adaptive stopping rule on Newton steps solved by CG (docs/theory.md, 18.3): each
    step's algebraic residual a = J dx - rhs, and eta_lin = C_F ||rho(R(u) - a)||."""

    system: SemismoothSystem
    stopping: Stopping
    algebraic: np.ndarray | None = None
    by_rule: bool = False
    eta_lin: float = float("nan")

    def krylov_rule(self, u: np.ndarray):
        """The rule on a step's CG from u: its residual r = rhs - J dx against eta_lin of the
        candidate u + dx (R(u + dx) less its linearised part -r), as the solve goes."""
        if not self.stopping.adaptive:
            return None
        return lambda r, dx: self.stopping.krylov_done(
            r, self.stopping.algebraic(self.system.residual(u + dx) + r))

    def record(self, algebraic: np.ndarray, by_rule: bool) -> None:
        self.algebraic, self.by_rule = algebraic, by_rule

    def settled(self, u: np.ndarray) -> bool:
        if not self.stopping.adaptive or self.algebraic is None:
            return False
        self.eta_lin = self.stopping.algebraic(self.system.residual(u) - self.algebraic)
        return self.by_rule and self.stopping.newton_done(self.eta_lin)


def system_matrix(system: SemismoothSystem, active: np.ndarray) -> sparse.csr_matrix:
    """The Jacobian K + T' D_A T on the full DOFs (tests and diagnostics)."""
    D, _ = system.phi_affine(active)
    return (system.K + system.T.T @ D @ system.T).tocsr()

"""``active-set`` for a ``SemismoothSystem`` (Nitsche): semismooth Newton on the contact values
(docs/theory.md, section 12.3).

The equation K u + T' phi(T u) = F (``formulations.semismooth``) is piecewise linear: fixing the
active set A = {q : P_q < 0} makes phi affine, phi = D_A z + c_A. With one factorisation of K
(u0 = K^-1 F) and M = T K^-1 T' from the back-end's Schur complement on the DOFs T touches (the
same route as the QP active-set solver), u = u0 - K^-1 T' phi(z) and the equation reduces to
the small dense one

    R(z) = z - z0 + M phi(z) = 0,   z0 = T u0,   Jacobian J_A = I + M D_A.

A semismooth Newton step from any z lands on J_A^-1 (z0 - M c_A), so the iteration is a
primal-dual active set method: it stops when the active set of the new iterate is the one it
was computed with (then R = 0 up to round-off: exact). It starts from the warm start's pressure
(nested iteration) or from the unconstrained solution's active set.

Safeguard: the plain iteration can cycle for a nonsymmetric J (theta != 1) or a small gamma_0.
When it revisits an active set or reaches ``max_iter``, it continues from the iterate with the
smallest |R| as a damped Newton method with Armijo backtracking on the merit |R|^2 (the
``safeguard`` diagnostic says so); if that fails too, the status is ``failed`` with the reason.
Back-ends without a Schur complement (splu) run the same iteration on the full sparse system
K + T' D_A T, factorised once per iteration.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy import linalg, sparse
from scipy.linalg.lapack import dgecon
from scipy.sparse.linalg import splu

from formulations.base import STATUS_FAILED, STATUS_OK, QPSolution, SolverDiagnostics
from formulations.semismooth import SemismoothSystem
from formulations.solvers.backends import check_backend, condenses, factorise_condensed
from formulations.solvers.registry import register_system_solver

MERIT_TOLERANCE = 1e-13  # |R| relative to |z0| + |M phi| at which the damped phase stops
ARMIJO = 1e-4


@dataclass(frozen=True)
class NewtonResult:
    x: np.ndarray
    status: str
    reason: str
    iterations: int
    changes: tuple[int, ...]
    cycled: bool
    safeguard: str
    condition: float


@dataclass(frozen=True, eq=False)
class Linearised:
    """The problem in the unknown x (z condensed, or u): R(x), P(x), and ``step(A, x)``: the
    Newton step -J_A^-1 R_A(x) of the affine equation R_A for the active set A (phi with A
    fixed; R_A = R where A is x's own active set), with the 1-norm condition estimate of J_A."""

    residual: Callable[[np.ndarray], np.ndarray]
    argument: Callable[[np.ndarray], np.ndarray]
    step: Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, float]]
    scale: Callable[[np.ndarray], float]


def dense_step(J: np.ndarray, rhs: np.ndarray) -> tuple[np.ndarray, float]:
    """J^-1 rhs and the 1-norm condition estimate of J from its LU factors."""
    lu, piv = linalg.lu_factor(J, check_finite=False)
    rcond, _ = dgecon(lu, np.abs(J).sum(axis=0).max(), norm="1")
    return linalg.lu_solve((lu, piv), rhs, check_finite=False), 1.0 / max(rcond, 1e-300)


def condensed_problem(system: SemismoothSystem, M: np.ndarray, z0: np.ndarray) -> Linearised:
    def residual(z):
        return z - z0 + M @ system.phi(z)

    def step(active, z):
        D, c = system.phi_affine(active)
        MD = (D.T @ M.T).T  # M D_A, D sparse
        r = z - z0 + MD @ z + M @ c
        return dense_step(np.eye(z0.size) + MD, -r)

    return Linearised(residual, system.pressure_argument, step,
                      lambda z: np.linalg.norm(z0) + np.linalg.norm(M @ system.phi(z)))


def sparse_problem(system: SemismoothSystem) -> Linearised:
    T = system.T

    def step(active, u):
        D, c = system.phi_affine(active)
        J = (system.K + T.T @ D @ T).tocsc()
        return splu(J).solve(-(J @ u + T.T @ c - system.F)), float("nan")

    return Linearised(system.residual, lambda u: system.pressure_argument(T @ u), step,
                      lambda u: np.linalg.norm(system.F) + np.linalg.norm(system.K @ u))


def newton(problem: Linearised, x: np.ndarray, active: np.ndarray,
           max_iter: int) -> NewtonResult:
    """The plain iteration from ``x`` with the first step's active set ``active``, then the
    damped safeguard (module docstring)."""
    changes, seen, condition = [], {active.tobytes()}, float("nan")
    best = (np.inf, x)
    for iteration in range(1, max_iter + 1):
        r = problem.residual(x)
        best = min(best, (np.linalg.norm(r), x), key=lambda b: b[0])
        dx, condition = problem.step(active, x)
        x = x + dx
        new = problem.argument(x) < 0
        changes.append(int((new != active).sum()))
        if changes[-1] == 0:
            return NewtonResult(x, STATUS_OK, "", iteration, tuple(changes), False, "",
                                condition)
        if new.tobytes() in seen:
            return damped(problem, best[1], iteration, tuple(changes), True,
                          "plain semismooth Newton revisited an active set")
        seen.add(new.tobytes())
        active = new
    return damped(problem, best[1], max_iter, tuple(changes), False,
                  f"plain semismooth Newton did not settle in {max_iter} iterations")


def damped(problem: Linearised, x: np.ndarray, done: int, changes: tuple[int, ...],
           cycled: bool, why: str, max_iter: int = 200) -> NewtonResult:
    """Newton with Armijo backtracking on |R|^2 from ``x``."""
    r = problem.residual(x)
    condition = float("nan")
    for iteration in range(1, max_iter + 1):
        if np.linalg.norm(r) <= MERIT_TOLERANCE * problem.scale(x):
            return NewtonResult(x, STATUS_OK, f"{why}; answered by damped Newton (safeguard)",
                                done + iteration, changes, cycled, "damped Newton", condition)
        active = problem.argument(x) < 0
        dx, condition = problem.step(active, x)
        t, norm = 1.0, np.linalg.norm(r)
        while True:
            trial = problem.residual(x + t * dx)
            if np.linalg.norm(trial) <= (1.0 - ARMIJO * t) * norm or t < 1e-12:
                break
            t *= 0.5
        if t < 1e-12:
            break
        x, r = x + t * dx, trial
        changes += (int(((problem.argument(x) < 0) != active).sum()),)
    return NewtonResult(x, STATUS_FAILED, f"{why}; damped Newton stalled at |R| = "
                        f"{np.linalg.norm(r):.2e}", done + max_iter, changes, cycled,
                        "damped Newton", condition)


@register_system_solver("active-set", "semismooth Newton (primal-dual active set) on the "
                                      "contact values, condensed from one factorisation")
def solve_semismooth(system: SemismoothSystem, warm_start: np.ndarray | None = None,
                     max_iter: int = 50, backend: str | None = None) -> QPSolution:
    """``warm_start``: a pressure per quadrature point (> 0 where active)."""
    start = time.perf_counter()
    backend = check_backend(backend)
    if warm_start is not None and np.shape(warm_start) != (system.nq,):
        raise ValueError(f"warm_start has shape {np.shape(warm_start)}, not ({system.nq},)")
    T = system.T
    if condenses(backend):
        factor = factorise_condensed(system.K, np.unique(T.indices), backend)
        clock = time.perf_counter()
        u0 = factor.solve(system.F)
        M = factor.condensed(T)
        z0 = T @ u0
        phases = [*factor.phases, ("condense", time.perf_counter() - clock)]
        problem, x = condensed_problem(system, M, z0), z0
    else:
        phases, problem, x = [], sparse_problem(system), np.zeros(system.n)
    active = (np.asarray(warm_start) > 0) if warm_start is not None else \
        problem.argument(x) < 0
    clock = time.perf_counter()
    result = newton(problem, x, active, max_iter)
    phases.append(("iterate", time.perf_counter() - clock))
    u = result.x
    if condenses(backend):
        clock = time.perf_counter()
        u = refine(system, factor.solve, M, u0 - factor.solve(T.T @ system.phi(result.x)))
        phases.append(("back-substitute", time.perf_counter() - clock))
    diagnostics = SolverDiagnostics(active_set_changes=result.changes, cycled=result.cycled,
                                    safeguard=result.safeguard,
                                    condition_estimate=result.condition, phases=tuple(phases))
    ok = result.status == STATUS_OK
    return QPSolution(u=u if ok else None, multipliers=system.pressure(u) if ok else None,
                      status=result.status, reason=result.reason, iterations=result.iterations,
                      solve_time=time.perf_counter() - start, solver="active-set",
                      backend=backend, diagnostics=diagnostics)


def refine(system: SemismoothSystem, solve: Callable, M: np.ndarray, u: np.ndarray,
           steps: int = 3) -> np.ndarray:
    """Iterative refinement of u in the full space with the final active set: the partial
    factorisation and the Schur complement leave |R(u)| ~1e-9 relative where a plain
    sparse solve leaves round-off. The correction solves (K + T' D T) du = -R(u) by the
    Woodbury form K^-1 - K^-1 T' D (I + M D)^-1 T K^-1 (two solves with the factor)."""
    T = system.T
    D, _ = system.phi_affine(system.pressure_argument(T @ u) < 0)
    lu = linalg.lu_factor(np.eye(M.shape[0]) + (D.T @ M.T).T, check_finite=False)
    r = system.residual(u)
    for _ in range(steps):
        y = -solve(r)
        du = y - solve(T.T @ (D @ linalg.lu_solve(lu, T @ y, check_finite=False)))
        trial = system.residual(u + du)
        if np.linalg.norm(trial) >= np.linalg.norm(r):
            break
        u, r = u + du, trial
    return u


def system_matrix(system: SemismoothSystem, active: np.ndarray) -> sparse.csr_matrix:
    """The Jacobian K + T' D_A T on the full DOFs (tests and diagnostics)."""
    D, _ = system.phi_affine(active)
    return (system.K + system.T.T @ D @ system.T).tocsr()

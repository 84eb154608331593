"""``active-set`` for a ``SemismoothSystem`` (Nitsche): semismooth Newton on the contact
pressure (docs/theory.md, section 12.3).

The equation K u + T' phi(T u) = F (``formulations.semismooth``) is piecewise linear: fixing the
active set A = {q : P_q < 0} makes phi affine. With one factorisation of K (u0 = K^-1 F) and
M = T K^-1 T' from the back-end's Schur complement on the DOFs T touches (the same route as the
QP active-set solver), u = u0 - K^-1 T' phi(z); eliminating sigma_nn at the quadrature points
(one nq x nq factorisation, ``reduced_pressure``) leaves an equation in m = [P]_- alone,

    R(m) = m - [P0 - G m]_- = 0,   Jacobian J_A = [[I + G_AA, G_AI], [0, I]],

so a step costs one |A| x |A| solve. A semismooth Newton step from any m lands on the solution
of the affine equation of its active set, so the iteration is a primal-dual active set method:
it stops when the active set of the new iterate is the one it was computed with (then R = 0 up
to round-off: exact). It starts from the warm start's pressure (nested iteration) or from the
unconstrained solution's active set; one step of iterative refinement in the full space
(``refine``) then removes what the partial factorisation leaves.

Safeguard: the plain iteration can cycle for a nonsymmetric J (theta != 1) or a small gamma_0.
When it revisits an active set or reaches ``max_iter``, it continues from the iterate with the
smallest |R| as a damped Newton method with Armijo backtracking on the merit |R|^2 (the
``safeguard`` diagnostic says so); if that fails too, the status is ``failed`` with the reason.
Back-ends without a Schur complement (splu) run the same iteration on u with the full sparse
Jacobian K + T' D_A T, factorised once per iteration; so does every back-end beyond
SPARSE_NEWTON_FROM points when that Jacobian is SPD (a penalty; theta = 1), where the dense
nq x nq block would cost O(nq^3) (``newton_route``); an iterative back-end (amg) always does.
On a direct back-end a step whose active set changed in few points tries CG preconditioned by
the last factorisation first (the Jacobians differ in a rank-one term per changed point;
``reused_factorisation``).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy import linalg
from scipy.linalg.lapack import dgecon

from formulations.base import STATUS_OK, QPSolution, SolverDiagnostics
from formulations.semismooth import SemismoothSystem
from formulations.solvers.backends import (
    FactorisationError,
    check_backend,
    condenses,
    factorise_condensed,
    iterative,
)
from formulations.solvers.newton import Linearised, newton
from formulations.solvers.registry import FAST_SOLVER, register_system_solver
from formulations.solvers.sparse_newton import sparse_problem
from formulations.solvers.stopping import FIXED_STOPPING, Stopping

# relative nonlinear residual at which iterative refinement stops (one step reaches 1e-13 ..
# 3e-12 from the ~1e-9 the partial factorisation leaves, measured to 5e5 DOFs)
REFINED = 1e-11
# Gauss points from which a system without S (a penalty) takes Newton steps on the sparse
# Jacobian instead of condensing: the dense Schur block costs O(nq^3), a step one sparse
# factorisation. Measured on the penalty's adaptive paper meshes (pardiso, warm starts, 3
# steps each): condensed 0.77 / 2.88 / 6.92 / 22.9 s against sparse 1.14 / 1.99 / 3.73 /
# 8.29 s at nq = 1068 / 1810 / 2556 / 4262 (86k to 504k DOFs)
SPARSE_NEWTON_FROM = 1500



def dense_step(J: np.ndarray, rhs: np.ndarray) -> tuple[np.ndarray, float]:
    """J^-1 rhs and the 1-norm condition estimate of J from its LU factors."""
    lu, piv = linalg.lu_factor(J, check_finite=False)
    rcond, _ = dgecon(lu, np.abs(J).sum(axis=0).max(), norm="1")
    return linalg.lu_solve((lu, piv), rhs, check_finite=False), 1.0 / max(rcond, 1e-300)


@dataclass(frozen=True, eq=False)
class ReducedPressure:
    """The condensed equation z = z0 - M phi(z) in m = [P]_- alone (docs/theory.md 12.3):
    with Theta = theta W / gamma, (I - M_SS Theta) s = s0 + (M_SN W - M_SS Theta) m, and
    P = s + gamma (g - v) becomes P = P0 - G m. G depends on M only; ``free(z0, gap)`` gives
    P0 (and s for m = 0) for any right-hand side, ``phi(s_free, m)`` phi from m."""

    system: SemismoothSystem
    L: tuple | None  # LU factors of I - M_SS Theta (None without S)
    LR: np.ndarray  # (I - M_SS Theta)^-1 (M_SN W - M_SS Theta)
    E: np.ndarray  # I - gamma M_NS Theta
    G: np.ndarray

    def free(self, z0: np.ndarray, gap: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        ns, gamma = self.system.ns, self.system.gamma
        if not ns:  # no sigma_nn term: P0 = gamma (g - v0)
            return gamma * (gap - z0), np.zeros(0)
        s_free = linalg.lu_solve(self.L, z0[:ns], check_finite=False)
        return self.E @ s_free + gamma * (gap - z0[ns:]), s_free

    def phi(self, s_free: np.ndarray, m: np.ndarray) -> np.ndarray:
        return self.system.phi_of(s_free + self.LR @ m, m)


def reduced_pressure(system: SemismoothSystem, M: np.ndarray) -> ReducedPressure:
    """The matrices of ``ReducedPressure`` from M = T K^-1 T' (one nq x nq factorisation;
    none without S, where M = M_NN and G = gamma M_NN W)."""
    nq, w, gamma = system.nq, system.weight, system.gamma
    if not system.ns:
        return ReducedPressure(system, None, np.zeros((0, nq)), np.zeros((nq, 0)),
                               gamma[:, None] * M * w[None, :])
    Mss, Msn, Mns, Mnn = M[:nq, :nq], M[:nq, nq:], M[nq:, :nq], M[nq:, nq:]
    Theta = system.theta * w / gamma
    L = linalg.lu_factor(np.eye(nq) - Mss * Theta[None, :], check_finite=False)
    LR = linalg.lu_solve(L, Msn * w[None, :] - Mss * Theta[None, :], check_finite=False)
    E = np.eye(nq) - gamma[:, None] * Mns * Theta[None, :]
    G = -(E @ LR + gamma[:, None] * (Mns * Theta[None, :] - Mnn * w[None, :]))
    return ReducedPressure(system, L, LR, E, G)


def active_solve(G: np.ndarray, active: np.ndarray, P0: np.ndarray) -> np.ndarray:
    """m with m_A = (I + G_AA)^-1 P0_A and 0 off A: the fixed point of m = chi (P0 - G m)."""
    m = np.zeros(P0.size)
    if active.any():
        m[active] = linalg.solve(np.eye(active.sum()) + G[np.ix_(active, active)], P0[active])
    return m


def condensed_problem(G: np.ndarray, P0: np.ndarray) -> Linearised:
    """R(m) = m - [P0 - G m]_-; for the active set A, J_A = [[I + G_AA, G_AI], [0, I]], so a
    step costs one |A| x |A| solve."""

    def residual(m):
        return m - np.minimum(P0 - G @ m, 0.0)

    def step(active, m):
        r = m - np.where(active, P0 - G @ m, 0.0)  # R_A(m)
        dm = -r  # rows off A: dm_I = -r_I
        if active.any():
            rhs = -r[active] - G[np.ix_(active, ~active)] @ dm[~active]
            dm[active], condition = dense_step(np.eye(active.sum()) + G[np.ix_(active, active)],
                                               rhs)
        else:
            condition = 1.0
        return dm, condition

    return Linearised(residual, lambda m: P0 - G @ m, step,
                      lambda m: np.linalg.norm(P0) + np.linalg.norm(G @ m))


def dense_block_size(system: SemismoothSystem, backend: str | None = None) -> int:
    """The columns of the dense Schur block ``solve_semismooth`` forms on ``backend`` (0: its
    route takes sparse steps, ``newton_route``)."""
    if not condenses(backend) or not newton_route(system, check_backend(backend))[0]:
        return 0
    return int(np.unique(system.T.indices).size)


@register_system_solver(FAST_SOLVER, "semismooth Newton (primal-dual active set) on the "
                                      "contact values, condensed from one factorisation",
                        meta={"dense_block_size": dense_block_size, "stopping": True,
                              "initial": True})
def solve_semismooth(system: SemismoothSystem, warm_start: np.ndarray | None = None,
                     max_iter: int = 50, backend: str | None = None,
                     stopping: Stopping = FIXED_STOPPING,
                     initial: np.ndarray | None = None) -> QPSolution:
    """``warm_start``: a pressure per quadrature point (> 0 where active); ``stopping``: when
    to stop (adaptive on the sparse-step routes; the condensed route stops when its active
    set settles); ``initial``: the displacement the sparse-step routes start from (nested
    iteration)."""
    start = time.perf_counter()
    backend = check_backend(backend)
    if warm_start is not None and np.shape(warm_start) != (system.nq,):
        raise ValueError(f"warm_start has shape {np.shape(warm_start)}, not ({system.nq},)")
    condensed, steps_on = newton_route(system, backend)
    try:
        u, result, phases, krylov, steps = run_newton(system, warm_start, max_iter, backend,
                                                      condensed, steps_on, stopping,
                                                      initial)
    except FactorisationError:  # a Jacobian with S that is not positive definite
        if condensed or not system.ns or iterative(backend) or not condenses(backend):
            raise
        u, result, phases, krylov, steps = run_newton(system, warm_start, max_iter, backend,
                                                      True, None, stopping)
    ok = result.status == STATUS_OK
    early = steps is not None and steps.stopping.adaptive and not result.safeguard and bool(
        result.changes and (result.changes[-1] != 0 or steps.by_rule and iterative(backend)))
    diagnostics = SolverDiagnostics(active_set_changes=result.changes, cycled=result.cycled,
                                    safeguard=result.safeguard,
                                    condition_estimate=result.condition, phases=tuple(phases),
                                    krylov_iterations=tuple(krylov), stopped_early=early,
                                    algebraic_residual=None if steps is None or not
                                    iterative(backend) else steps.algebraic)
    return QPSolution(u=u if ok else None, multipliers=system.pressure(u) if ok else None,
                      status=result.status, reason=result.reason, iterations=result.iterations,
                      solve_time=time.perf_counter() - start, solver=FAST_SOLVER,
                      backend=backend, diagnostics=diagnostics)


def newton_route(system: SemismoothSystem, backend: str) -> tuple[bool, str | None]:
    """(condensed, the back-end of the sparse steps; None: SuperLU). Condensed while the dense
    nq x nq block is cheap (nq <= SPARSE_NEWTON_FROM); beyond, sparse steps on the back-end when
    the Jacobian is SPD: no S (a penalty), or theta = 1 (symmetric, positive definite for a
    stable gamma_0; if the factorisation finds it is not, the condensed route answers). An
    iterative back-end always takes sparse steps; splu takes them with SuperLU."""
    if iterative(backend):
        return False, backend
    if not condenses(backend):
        return False, None if system.ns else backend
    if system.nq <= SPARSE_NEWTON_FROM or (system.ns and system.theta != 1.0):
        return True, None
    return False, backend


def run_newton(system: SemismoothSystem, warm_start, max_iter: int, backend: str,
               condensed: bool, steps_on: str | None, stopping: Stopping = FIXED_STOPPING,
               initial: np.ndarray | None = None):
    """(u, NewtonResult, phases, Krylov iterations, the stopping rule's state or None) on the
    route ``newton_route`` chose."""
    T = system.T
    if condensed:
        factor = factorise_condensed(system.K, np.unique(T.indices), backend)
        clock = time.perf_counter()
        u0 = factor.solve(system.F)
        reduced = reduced_pressure(system, factor.condensed(T))
        P0, s_free = reduced.free(T @ u0, system.gap)
        phases = [*factor.phases, ("condense", time.perf_counter() - clock)]
        problem, x = condensed_problem(reduced.G, P0), np.zeros(system.nq)
    else:
        phases = []
        x = np.array(initial, dtype=float) if initial is not None and initial.size == \
            system.n else np.zeros(system.n)
        problem = sparse_problem(system, steps_on, stopping)
    active = (np.asarray(warm_start) > 0) if warm_start is not None else \
        problem.argument(x) < 0
    clock = time.perf_counter()
    result = newton(problem, x, active, max_iter)
    phases.append(("iterate", time.perf_counter() - clock))
    u = result.x
    if result.status == STATUS_OK and condensed:
        clock = time.perf_counter()
        u = refine(system, factor.solve, reduced,
                   u0 - factor.solve(T.T @ reduced.phi(s_free, result.x)))
        phases.append(("back-substitute", time.perf_counter() - clock))
    return u, result, phases, problem.krylov, problem.adaptive


def refine(system: SemismoothSystem, solve: Callable, reduced: ReducedPressure, u: np.ndarray,
           steps: int = 3) -> np.ndarray:
    """Iterative refinement of u in the full space with the final active set A: the partial
    factorisation and the Schur complement leave |R(u)| ~1e-9 relative where a plain sparse
    solve leaves round-off. The correction du = y - K^-1 T' phi, y = -K^-1 R(u), solves
    (K + T' D_A T) du = -R(u): phi is that of the linear equation dz = T y - M phi(dz) (the
    reduced one with zero gap), two solves with the factor and one |A| x |A| solve a step."""
    T = system.T
    active = system.pressure_argument(T @ u) < 0
    r, scale = system.scaled_residual(u)
    for _ in range(steps):
        if np.linalg.norm(r) <= REFINED * scale:
            break
        y = -solve(r)
        P0, s_free = reduced.free(T @ y, np.zeros(system.nq))
        du = y - solve(T.T @ reduced.phi(s_free, active_solve(reduced.G, active, P0)))
        trial, trial_scale = system.scaled_residual(u + du)
        if np.linalg.norm(trial) >= np.linalg.norm(r):
            break
        u, r, scale = u + du, trial, trial_scale
    return u

"""The primal-dual active set iteration for an iterative back-end (``amg``): each active set's
equality-constrained problem is solved by projected preconditioned conjugate gradients, with
no factorisation of K and no dense block (docs/theory.md, section 16).

For the active rows B_A the constrained minimiser of 1/2 u'Ku - F'u subject to B_A u = G_A is
u = u_p + w with u_p = B_A' (B_A B_A')^-1 G_A and w in ker B_A. The orthogonal projection
Pi = I - B_A' (B_A B_A')^-1 B_A onto ker B_A needs only the small sparse Gram matrix B_A B_A'
(diagonal for the vi's nodal rows; banded for the mixed method's), factorised once per set.
Conjugate gradients on ker B_A with the preconditioner Pi M^-1 Pi (M: the multigrid cycle of
K) converge like the unconstrained CG (Gould, Hribar and Nocedal 2001). The multipliers are
lambda_A = (B_A B_A')^-1 B_A (F - K u), the least-squares solution of K u + B_A' lambda_A = F.

The active-set update is the augmented iteration's (``augmented``): keep the active rows with
lambda_i > 0, add the inactive rows the new u violates; each set's CG starts from the last u.
Inexact while searching: CG stops at SEARCH_RTOL until the set stops changing, then the set is
solved to the back-end's RTOL and the update is checked again with that u (so the answer is
the exact one of the last set, as on the direct routes).
The iterative solve leaves multipliers exact to about the solve's relative residual, so a row
whose multiplier is zero to that accuracy keeps its place (no flip-flop on weakly active rows).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from scipy import sparse
from scipy.sparse.linalg import splu

from formulations.base import STATUS_FAILED, STATUS_OK, ContactQP, SolverDiagnostics
from formulations.solvers.augmented import VIOLATION_TOLERANCE
from formulations.solvers.backends import FactorisationError, factorise
from formulations.solvers.backends.amg import MAX_ITERATIONS, RTOL
from formulations.solvers.lcp import SINGULAR
from formulations.solvers.stopping import FIXED_STOPPING, QPLinearisation, Stopping

WEAKLY_ACTIVE = 1e-8  # |lambda_i| / max |lambda| below which a multiplier is zero (solve accuracy)
# CG's relative residual while the active set is still changing: the set a step predicts
# depends on u only near the contact zone's ends, which a looser solve already resolves.
# vi P1 on paper-3d, V-cycles in all with 1e-4 / 1e-3 / 1e-2: 56 / 47 / - at 13 872 DOFs,
# 120 / 99 / - at 104 544, 178 / 143 / 157 at 545 832, the same sets with 1e-4 and 1e-3;
# with 1e-2 the set that looked settled changed again once solved exactly
SEARCH_RTOL = 1e-3
# CG solves of one set under the adaptive rule: its eta_alg criterion uses eta_lin, which the
# solve itself changes; re-solved while eta_lin fell (twice at most was measured)
RESOLVES = 4


def projection(B_A: sparse.csr_matrix):
    """(Pi, particular) for the rows B_A: x -> Pi x, and G_A -> B_A' (B_A B_A')^-1 G_A."""
    if B_A.shape[0] == 0:
        return (lambda x: x), (lambda g: np.zeros(B_A.shape[1])), (lambda r: np.zeros(0))
    gram = splu(sparse.csc_matrix(B_A @ B_A.T))

    def project(x):
        return x - B_A.T @ gram.solve(B_A @ x)

    return project, (lambda g: B_A.T @ gram.solve(g)), (lambda r: gram.solve(B_A @ r))


def projected_cg(K, precondition, project, F: np.ndarray, u: np.ndarray, rtol: float,
                 counts: list[int], done=None) -> tuple[np.ndarray, str]:
    """min 1/2 u'Ku - F'u on the affine set of ``u`` (u + ker B_A) by preconditioned CG, to
    the relative residual ``rtol`` or until ``done(r)`` (the stopping rule's, on the
    residual r = F - K u - B_A' lambda_A); (u, "rule" if ``done`` stopped it, else
    "tolerance")."""
    r = project(F - K @ u)
    # |F| + |K u|: the scale of the balance, also when the load is the obstacle's (F = 0)
    norm = np.linalg.norm(F) + np.linalg.norm(K @ u)
    z = project(precondition(r))
    p, rz = z.copy(), r @ z
    for iteration in range(1, MAX_ITERATIONS + 1):
        met = done is not None and done(r)
        if met or np.linalg.norm(r) <= rtol * norm:
            counts.append(iteration - 1)
            return u, "rule" if met else "tolerance"
        Kp = K @ p
        alpha = rz / (p @ Kp)
        u = u + alpha * p
        r = r - alpha * project(Kp)
        z = project(precondition(r))
        rz, rz_old = r @ z, rz
        p = z + (rz / rz_old) * p
    residual = np.linalg.norm(project(F - K @ u)) / norm
    raise FactorisationError(f"amg: projected CG reached a relative residual of "
                             f"{residual:.1e}, not {rtol:.0e}, in {MAX_ITERATIONS} iterations")


def next_active_set(qp: ContactQP, active: np.ndarray, u: np.ndarray, K, multipliers):
    """(lambda, the next active set) from u solved on ``active`` (module docstring)."""
    lam = np.zeros(qp.m)
    lam[np.flatnonzero(active)] = multipliers(qp.F - K @ u)
    return lam, next_rows(qp, active, u, lam)


def next_rows(qp: ContactQP, active: np.ndarray, u: np.ndarray, lam: np.ndarray) -> np.ndarray:
    """The augmented update: keep the active rows whose multiplier is not negative (to the
    solve's accuracy), add the inactive rows that u violates."""
    slack = qp.G - qp.B @ u
    scale = max(np.abs(u).max(initial=0.0), qp.gap_scale, np.finfo(float).tiny)
    zero = WEAKLY_ACTIVE * np.abs(lam).max(initial=0.0)
    return np.where(active, lam > -zero, slack < -VIOLATION_TOLERANCE * scale)


def settled_multipliers(lam: np.ndarray, rows: np.ndarray, changes: int) -> np.ndarray:
    """The multipliers returned: on a set that settled, the active rows' zero-to-accuracy
    ones exactly zero (as on the fixed route); an early stop keeps the signs it has."""
    if changes == 0:
        lam[rows] = np.maximum(lam[rows], 0.0)
    return lam


def solve_set(qp: ContactQP, K, precondition, project, multipliers, active: np.ndarray,
              u: np.ndarray, rtol: float, counts: list[int], stopping: Stopping,
              eta_lin: float, linearisation: QPLinearisation) -> tuple[np.ndarray, str, float]:
    """CG on one active set from ``u``: (u, how it ended, eta_lin). Under an adaptive rule
    the solve ends by its eta_alg criterion, which uses eta_lin, which the solve itself
    changes: solved on while eta_lin falls."""
    for _ in range(RESOLVES):
        done = (lambda r, e=eta_lin: stopping.krylov_done(r, e)) if stopping.adaptive \
            else None
        u, how = projected_cg(K, precondition, project, qp.F, u, rtol, counts, done)
        if not stopping.adaptive:
            break
        lam, _ = next_active_set(qp, active, u, K, multipliers)
        was, eta_lin = eta_lin, linearisation(u, lam, stopping.load_norm)
        if how != "rule" or not eta_lin < was:
            break
    return u, how, eta_lin


def solve_projected(qp: ContactQP, active: np.ndarray, max_iter: int, backend: str,
                    stopping: Stopping = FIXED_STOPPING, initial: np.ndarray | None = None):
    """(u, lambda, iterations, status, reason, diagnostics) as ``solve_augmented`` returns
    them; the diagnostics hold the CG iterations of every active set. While the set changes,
    CG stops at SEARCH_RTOL; a set that stays is solved again to RTOL and checked again.
    An adaptive ``stopping`` also ends each CG solve by its eta_alg criterion and the
    iteration at the first iterate whose eta_lin meets its criterion (docs/theory.md, 18.3).
    ``initial``: the first u (its first entries; nested iteration), else 0."""
    precondition = factorise(qp.K, backend, qp.near_null).preconditioner.matvec
    K = sparse.csr_matrix(qp.K)
    seen, changes, counts = set(), [], []
    u, lam = np.zeros(qp.n), np.zeros(qp.m)
    rtol = RTOL if stopping.adaptive else SEARCH_RTOL  # adaptive: the rule ends every solve
    if initial is not None:
        u[:min(initial.size, qp.n)] = initial[:qp.n]
    linearisation, eta_lin = QPLinearisation(K, qp.B, qp.G), float("nan")

    def diagnostics(cycled):
        return SolverDiagnostics(active_set_changes=tuple(changes), cycled=cycled,
                                 krylov_iterations=tuple(counts))

    for iteration in range(1, max_iter + 1):
        if (active.tobytes(), rtol) in seen and (stopping.adaptive or rtol > RTOL):
            # inexact solves cycled between sets (a weakly active row they cannot decide):
            # go on with exact ones, as the fixed tolerances would once the set settled
            stopping, rtol, seen = FIXED_STOPPING, RTOL, set()
        if (active.tobytes(), rtol) in seen:
            return (u, lam, iteration - 1, STATUS_FAILED, "active set cycles (a set repeated)",
                    diagnostics(True))
        seen.add((active.tobytes(), rtol))
        rows = np.flatnonzero(active)
        try:
            project, particular, multipliers = projection(qp.B[rows])
        except RuntimeError:  # dependent active rows: B_A B_A' singular
            return u, lam, iteration, STATUS_FAILED, SINGULAR, diagnostics(False)
        u_p = particular(qp.G[rows])
        if not np.any(qp.F) and not np.any(u_p):  # no load, no gap to close: u = 0 exactly
            u, counts, solved, how = np.zeros(qp.n), counts + [0], True, "tolerance"
        else:  # the last u, moved onto the new set
            u, how, eta_lin = solve_set(qp, K, precondition, project, multipliers, active,
                                        project(u) + u_p, rtol, counts, stopping, eta_lin,
                                        linearisation)
            solved = how == "rule" or rtol <= RTOL
        lam, new_active = next_active_set(qp, active, u, K, multipliers)
        changes.append(int((new_active != active).sum()))
        if stopping.adaptive:
            eta_lin = linearisation(u, lam, stopping.load_norm)
            if solved and (changes[-1] == 0 or stopping.newton_done(eta_lin)):
                return (u, settled_multipliers(lam, rows, changes[-1]), iteration, STATUS_OK,
                        "", replace(diagnostics(False),
                                    stopped_early=changes[-1] != 0 or how == "rule"))
        if changes[-1] == 0 and rtol == RTOL:  # settled and exact
            return u, settled_multipliers(lam, rows, 0), iteration, STATUS_OK, "", \
                diagnostics(False)
        if changes[-1] == 0:
            rtol = RTOL  # the set has settled: solve it exactly
        active = new_active
    return (u, lam, max_iter, STATUS_FAILED,
            f"active set still changing after {max_iter} iterations", diagnostics(False))

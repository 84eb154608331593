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
The first active set is {i : r_i > 0} (the constraints the unconstrained solution violates)
unless ``warm_start`` multipliers are given: then it is {i : warm_start_i > 0}, which is how the
refinement loop's nested iteration passes the previous level's contact zone.

Safeguard. The plain iteration is not globally convergent: it can cycle (``lcp``). When it
cycles or hits ``max_iter``, the condensed route switches to Murty's least-index principal
pivoting from the last active set, which terminates for every SPD S; if that also fails, and on
the augmented (splu) route at once, the problem is handed to the reference solver. The
``safeguard`` diagnostic names what produced the answer ("" for the plain iteration,
"least-index pivoting", "reference fallback") and the reason says why it was needed; the answer
is judged by its own KKT residuals like any other.

Diagnostics (``QPSolution.diagnostics``): the active-set changes of every iteration, the
cycling flag, the safeguard, and ``condition_estimate``: the 1-norm condition number of the
last system the iteration solved, in the solver's scaling (rows of B divided by row_scale):
the active block of the condensed S (pardiso, cholmod) or the saddle-point matrix (splu,
estimated).
"""

from __future__ import annotations

import time
from dataclasses import replace

import numpy as np
from scipy import sparse

from formulations.base import STATUS_OK, ContactQP, QPSolution, SolverDiagnostics
from formulations.solvers.augmented import initial_active_set, solve_augmented
from formulations.solvers.backends import (
    check_backend,
    condenses,
    factorise_condensed,
    iterative,
)
from formulations.solvers.friction import condensed_rows, solve_frictional
from formulations.solvers.lcp import CYCLING_EXAMPLE, condition_1, least_index_pivoting, pdas
from formulations.solvers.projected import solve_projected
from formulations.solvers.reference import solve_reference
from formulations.solvers.registry import FAST_SOLVER, register_solver
from formulations.solvers.stopping import FIXED_STOPPING, QPLinearisation, Stopping


def _fallback(qp: ContactQP, why: str, diagnostics: SolverDiagnostics,
              start: float) -> QPSolution:
    """The last resort: the reference solver, with the plain iteration's diagnostics."""
    answer = solve_reference(qp)
    reason = f"{why}; answered by the reference solver (safeguard)"
    if answer.reason:
        reason += f": {answer.reason}"
    return replace(answer, solver=FAST_SOLVER, reason=reason,
                   solve_time=time.perf_counter() - start,
                   diagnostics=replace(diagnostics, safeguard="reference fallback"))


def _uncondensed(qp: ContactQP, warm_start, max_iter: int, backend: str, stopping: Stopping,
                 initial, start: float) -> QPSolution:
    """The iteration on a back-end without a Schur complement: projected CG (iterative) or
    the augmented system (splu), the reference solver if it fails."""
    active = (np.asarray(warm_start) > 0) if warm_start is not None else \
        initial_active_set(qp, backend)
    u, lam, iterations, status, reason, diagnostics = (
        solve_projected(qp, active, max_iter, backend, stopping, initial)
        if iterative(backend) else solve_augmented(qp, active, max_iter, stopping))
    if status != STATUS_OK:
        return _fallback(qp, f"plain active set failed ({reason})", diagnostics, start)
    return QPSolution(u=u, multipliers=lam, status=status, reason=reason,
                      iterations=iterations, solve_time=time.perf_counter() - start,
                      solver=FAST_SOLVER, backend=backend, diagnostics=diagnostics)


def dense_block_size(qp: ContactQP, backend: str | None = None) -> int:
    """The columns of the dense Schur block ``solve_active_set`` forms on ``backend`` (0: the
    back-end does not condense): every DOF the constraint rows touch, and the tangential rows'
    too with friction."""
    if not condenses(backend):
        return 0
    rows = qp.B if qp.friction is None else condensed_rows(qp)
    return int(np.unique(rows.indices).size)


@register_solver(FAST_SOLVER, "primal-dual active set (semismooth Newton): condensed "
                              "B K^-1 B' from one factorisation (pardiso, cholmod), the "
                              "augmented saddle-point system (splu) or projected CG with "
                              "multigrid (amg); nested iteration",
                 meta={"dense_block_size": dense_block_size, "stopping": True,
                       "initial": True})
def solve_active_set(qp: ContactQP, warm_start: np.ndarray | None = None,
                     max_iter: int = 100, backend: str | None = None,
                     stopping: Stopping = FIXED_STOPPING,
                     initial: np.ndarray | None = None) -> QPSolution:
    """``backend``: 'pardiso' or 'cholmod' (condensed iteration), 'splu' (augmented
    iteration, see ``augmented``) or 'amg' (projected CG, see ``projected``); default: the
    fastest available, see ``backends``. ``stopping``: when to stop (``stopping``; adaptive
    on the frictionless condensed and projected routes); ``initial``: the displacement the
    projected route starts from (nested iteration; a slack form's slacks start at 0)."""
    start = time.perf_counter()
    backend = check_backend(backend)
    if warm_start is not None and np.shape(warm_start) != (qp.m,):
        raise ValueError(f"warm_start has shape {np.shape(warm_start)}, not ({qp.m},)")
    if qp.friction is not None:
        answer = solve_frictional(qp, warm_start, max_iter, backend)
        if answer.status == STATUS_OK or qp.friction.coulomb:
            return answer
        return _fallback(qp, answer.reason, answer.diagnostics, start)
    if not condenses(backend):
        return _uncondensed(qp, warm_start, max_iter, backend, stopping, initial, start)
    factor = factorise_condensed(qp.K, np.unique(qp.B.indices), backend)
    clock = time.perf_counter()
    u0 = factor.solve(qp.F)
    S = factor.condensed(qp.B)
    r = qp.B @ u0 - qp.G
    phases = [*factor.phases, ("condense", time.perf_counter() - clock)]
    clock = time.perf_counter()
    active = (np.asarray(warm_start) > 0) if warm_start is not None else (r > 0)
    result = pdas(S, r, active, max_iter, settled(qp, stopping))
    diagnostics = SolverDiagnostics(active_set_changes=tuple(result.changes),
                                    cycled=result.cycled,
                                    stopped_early=bool(result.changes and result.changes[-1]))
    reason, iterations = "", result.iterations
    if result.status != STATUS_OK:
        reason = f"plain active set failed ({result.reason})"
        result = least_index_pivoting(S, r, result.active, 20 * qp.m + 100)
        iterations += result.iterations
        diagnostics = replace(diagnostics, safeguard="least-index pivoting",
                              active_set_changes=diagnostics.active_set_changes
                              + tuple(result.changes))
        if result.status != STATUS_OK:
            return _fallback(qp, f"{reason}, then {result.reason}", diagnostics, start)
        reason += "; answered by least-index pivoting (safeguard)"
    phases.append(("iterate", time.perf_counter() - clock))
    clock = time.perf_counter()
    scaled = S / np.outer(qp.row_scale, qp.row_scale)  # the solver's units, as for splu
    condition = condition_1(scaled, result.active)
    phases.append(("condition", time.perf_counter() - clock))
    clock = time.perf_counter()
    u = factor.solve(qp.F - qp.B.T @ result.lam)
    phases.append(("back-substitute", time.perf_counter() - clock))
    # S = B K^-1 B' is kept: formulations.diagnostics reuses it for the inf-sup constant
    diagnostics = replace(diagnostics, condition_estimate=condition, condensed=S,
                          phases=tuple(phases))
    return QPSolution(u=u, multipliers=result.lam, status=STATUS_OK, reason=reason,
                      iterations=iterations, solve_time=time.perf_counter() - start,
                      solver=FAST_SOLVER, backend=factor.backend, diagnostics=diagnostics)


def settled(qp: ContactQP, stopping: Stopping):
    """The condensed iteration's early end under an adaptive ``stopping`` (None: fixed): its
    slack y = G - B u and multipliers give eta_lin without a back-substitution."""
    if not stopping.adaptive:
        return None
    linearisation = QPLinearisation(qp.K, qp.B, qp.G)
    return lambda lam, y: stopping.newton_done(
        linearisation.measure(-y, lam, stopping.load_norm))


def cycling_qp() -> ContactQP:
    """A contact QP whose condensed system is ``lcp.CYCLING_EXAMPLE``: K = S^-1, B = I, F = 0,
    G = -r (so B K^-1 B' = S and B u0 - G = r); start it from the example's active set
    (``warm_start``) to make the plain iteration cycle."""
    S, r, _ = CYCLING_EXAMPLE
    return ContactQP(K=sparse.csr_matrix(np.linalg.inv(S)), F=np.zeros(r.size),
                     B=sparse.identity(r.size, format="csr"), G=-r, row_scale=np.ones(r.size),
                     objective_scale=1.0)

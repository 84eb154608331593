"""The fast frictional solve: condensed primal-dual active sets on stick, slip and separation
(docs/theory.md, 17.3).

With C = [B; T] (normal rows, then the tangential rows of the same nodes), u = K^-1 (F - C'lam)
and the Tresca problem's dual is the box QP

    min 1/2 lam'S lam - r'lam,  S = C K^-1 C',  r = C K^-1 F - [G; w],
    lam_n >= 0,  -b <= lam_t <= b,

with w the obstacle's tangential displacement (0 unless it slides), solved exactly by
``box.box_pdas`` (the slack r - S lam is [Bu - G; Tu - w]: a free normal entry is
a node in contact, a free tangential one a node that sticks, one at a bound a node that slips).
K is factorised once and S comes from the same factorisation, as in the frictionless
``active_set``; Coulomb's fixed point (``coulomb``) reuses both for every step, so a Coulomb
level costs one factorisation too. Two tangential directions per node (3D) make the bound a
disc, not a box: the same condensed problem is then solved by semismooth Newton
(``disc.disc_ssn``), warm-started by the previous Coulomb step. An iterative back-end, which
would form S one Krylov solve per row of C, runs the iteration on the primal side instead
(``projected_friction``).
"""

from __future__ import annotations

import time
from dataclasses import replace

import numpy as np
from scipy import sparse

from formulations.base import STATUS_OK, ContactQP, QPSolution, SolverDiagnostics
from formulations.solvers.backends import (
    check_backend,
    condenses,
    factorise,
    factorise_condensed,
    iterative,
)
from formulations.solvers.box import (
    AT_LOWER,
    FREE,
    BoxResult,
    box_bvls,
    box_pdas,
    initial_state,
)
from formulations.solvers.coulomb import coulomb_fixed_point
from formulations.solvers.disc import disc_ssn
from formulations.solvers.projected_friction import solve_projected_tresca, split_preconditioner
from formulations.solvers.registry import FAST_SOLVER

# the exact active-set steps leave round-off; the fixed point stops when the bound has settled
COULOMB_RTOL = 1e-11


class FrictionError(ValueError):
    """A frictional problem this solver does not handle."""


def condensed_rows(qp: ContactQP) -> sparse.csr_matrix:
    """The rows the frictional solvers condense onto: B's, then the tangential ones."""
    return sparse.vstack([qp.B, qp.friction.T], format="csr")


def condensed_system(qp: ContactQP, backend: str):
    """(solve, S, r, phases): a factorisation of K, the condensed C K^-1 C' and its right-hand
    side, on a direct back-end (an iterative one takes ``solve_without_factorisation``)."""
    C = condensed_rows(qp)
    clock = time.perf_counter()
    if condenses(backend):
        factor = factorise_condensed(qp.K, np.unique(C.indices), backend)
        solve, S, phases = factor.solve, factor.condensed(C), list(factor.phases)
    else:
        solve = factorise(qp.K, backend, qp.near_null)
        S, phases = np.asarray(C @ solve(C.T.toarray())), []
    u0 = solve(qp.F)
    shift = qp.friction.shift
    r = C @ u0 - np.concatenate([qp.G, np.zeros(qp.friction.T.shape[0]) if shift is None
                                 else shift])
    phases.append(("condense", time.perf_counter() - clock))
    return solve, C, S, r, phases


def tresca_step(S: np.ndarray, r: np.ndarray, qp: ContactQP, previous: QPSolution | None,
                warm_start: np.ndarray | None, max_iter: int):
    """One Tresca box solve (``box.BoxResult``). Starts, in turn until one converges: the
    previous step's sets (a node pinned there by a zero bound sticks instead), the warm
    start's contact zone with every node sticking, the unconstrained solution's sets. The
    iteration is not globally convergent (it can cycle from a poor start, as the frictionless
    one can), and the next start is then tried; if every start fails, bounded least squares
    (``box.box_bvls``) finds the sets."""
    m, bound = qp.m, qp.friction.bound  # a Tresca step: Coulomb's steps have their bound
    lower = np.concatenate([np.zeros(m), -bound])
    upper = np.concatenate([np.full(m, np.inf), bound])
    starts = []
    if previous is not None and previous.diagnostics.sets is not None:
        sets = previous.diagnostics.sets.copy()
        sets[m:] = np.where(sets[m:] == AT_LOWER, FREE, sets[m:])
        starts.append(sets)
    if warm_start is not None:
        starts.append(np.concatenate([np.where(np.asarray(warm_start) > 0, FREE, AT_LOWER),
                                      np.full(bound.size, FREE)]))
    starts.append(initial_state(r, lower, upper))
    changes, cycled = (), False
    for state in starts:
        result = box_pdas(S, r, lower, upper, state, max_iter)
        changes, cycled = changes + result.changes, cycled or result.cycled
        if result.status == STATUS_OK:
            return replace(result, changes=changes, cycled=cycled)
    result = box_bvls(S, r, lower, upper, max_iter)
    return replace(result, changes=changes + result.changes, cycled=cycled)


def disc_step(S: np.ndarray, r: np.ndarray, qp: ContactQP, previous: QPSolution | None,
              max_iter: int) -> BoxResult:
    """One Tresca solve with discs (3D), from the previous step's multipliers if any."""
    start = None
    if previous is not None and previous.u is not None:
        start = np.concatenate([previous.multipliers, previous.tangential])
    result = disc_ssn(S, r, qp.m, qp.friction.bound, start, max_iter)
    return BoxResult(result.lam, None, result.iterations, result.status,
                     result.reason and f"semismooth Newton on the discs: {result.reason}", (),
                     False)


def solve_frictional(qp: ContactQP, warm_start: np.ndarray | None = None, max_iter: int = 100,
                     backend: str | None = None) -> QPSolution:
    """Tresca or Coulomb (a fixed point on the bound, ``coulomb``) on one factorisation."""
    if qp.friction.block not in (1, 2):
        raise FrictionError(f"friction with {qp.friction.block} tangential directions per "
                            "node: only 1 (2D, a box) and 2 (3D, a disc) are solved")
    start = time.perf_counter()
    backend = check_backend(backend)
    if iterative(backend):
        return solve_without_factorisation(qp, warm_start, max_iter, backend)
    solve, C, S, r, phases = condensed_system(qp, backend)

    def tresca(step_qp: ContactQP, previous: QPSolution | None) -> QPSolution:
        clock = time.perf_counter()
        result = (disc_step(S, r, step_qp, previous, max_iter) if qp.friction.block == 2
                  else tresca_step(S, r, step_qp, previous, warm_start, max_iter))
        diagnostics = SolverDiagnostics(active_set_changes=result.changes,
                                        cycled=result.cycled, sets=result.state,
                                        safeguard=result.safeguard)
        if result.status != STATUS_OK:
            return QPSolution(None, None, result.status, f"frictional active set failed "
                              f"({result.reason})", result.iterations,
                              time.perf_counter() - clock, FAST_SOLVER, backend, diagnostics)
        u = solve(qp.F - C.T @ result.lam)
        return QPSolution(u=u, multipliers=result.lam[:qp.m], status=STATUS_OK, reason="",
                          iterations=result.iterations, solve_time=time.perf_counter() - clock,
                          solver=FAST_SOLVER, backend=backend, diagnostics=diagnostics,
                          tangential=result.lam[qp.m:])

    answer = (coulomb_fixed_point(qp, tresca, COULOMB_RTOL) if qp.friction.coulomb
              else tresca(qp, None))
    phases.append(("iterate", answer.solve_time))
    return replace(answer, solve_time=time.perf_counter() - start,
                   diagnostics=replace(answer.diagnostics, phases=tuple(phases)))


def solve_without_factorisation(qp: ContactQP, warm_start: np.ndarray | None, max_iter: int,
                                backend: str) -> QPSolution:
    """Tresca or Coulomb on an iterative back-end (``projected_friction``): one multigrid
    hierarchy of K for every step of every Tresca problem."""
    start = time.perf_counter()
    precondition = split_preconditioner(qp, backend)
    phases, counts = [("hierarchy", time.perf_counter() - start)], []

    def tresca(step_qp: ContactQP, previous: QPSolution | None) -> QPSolution:
        step = solve_projected_tresca(step_qp, precondition, previous, warm_start, max_iter)
        counts.extend(step.diagnostics.krylov_iterations)
        return step

    answer = (coulomb_fixed_point(qp, tresca, COULOMB_RTOL) if qp.friction.coulomb
              else tresca(qp, None))
    phases.append(("iterate", answer.solve_time))
    return replace(answer, solve_time=time.perf_counter() - start, backend=backend,
                   diagnostics=replace(answer.diagnostics, phases=tuple(phases),
                                       krylov_iterations=tuple(counts)))

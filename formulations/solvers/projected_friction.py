"""Tresca friction without a factorisation: the primal-dual active set on separation, stick and
slip for an iterative back-end (``amg``), each step a projected CG solve of the full system
(docs/theory.md, 17.3, "Without a factorisation").

The condensed route (``friction``) needs S = C K^-1 C', which an iterative back-end can only
build column by column, one Krylov solve per row of C. Here K is never inverted. With the
slack y = C u - [G; w] and z = lambda + c y, a step fixes

- the normal rows in contact: B_i u = G_i (the augmented update of ``projected``); the others
  carry lambda_n,i = 0;
- the nodes that stick (|z_t,i| <= b_i): T_i u = w_i;
- the nodes that slip: lambda_t,i = b_i d_i + kappa_i (I - d_i d_i')(T_i u - w_i), with
  d_i = z_t,i / |z_t,i|, kappa_i = c q_i / (1 - q_i), q_i = b_i / |z_t,i|: the semismooth
  Newton linearisation of lambda_t = P_disc(z_t), a spring across the slip direction (none in
  2D, where the step is the box PDAS of ``box`` on the primal side),

and solves the equality-constrained problem with the springs added to K by projected CG
(``projected.projected_cg``, preconditioned by K's V-cycle); the equality rows' multipliers are
the least-squares ones. c is small (COUPLING of the rows' scale), so that a node whose slip
reverses sticks before it slips the other way. CG stops at SEARCH_RTOL while the sets change
or a direction moves by more than SEARCH_DIRECTION, then at the back-end's RTOL until the sets
repeat and no direction moves by more than DIRECTION_TOLERANCE: the answer is the exact solve
of its sets.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
from scipy import sparse

from formulations.base import STATUS_FAILED, STATUS_OK, ContactQP, QPSolution, SolverDiagnostics
from formulations.solvers.backends import FactorisationError, factorise
from formulations.solvers.backends.amg import RTOL
from formulations.solvers.lcp import SINGULAR
from formulations.solvers.projected import WEAKLY_ACTIVE, next_rows, projected_cg, projection
from formulations.solvers.registry import FAST_SOLVER

# the largest move of a slip direction (unit vectors) at which the directions count as
# settled: a force b d off by this much moves u by about as much, relative, below the 1e-8 in
# energy that the back-end promises
DIRECTION_TOLERANCE = 1e-10
# CG's relative residual while the sets or directions change: tighter than frictionless
# contact's 1e-3, because the slip directions follow the tangential forces. V-cycles in all
# with 1e-4 / 1e-3, P1 at 13 872 DOFs: stick-slip-3d vi 277 / 331, mixed 195 / 352; paper-3d
# Coulomb (mu 0.3) vi 685 / 725
SEARCH_RTOL = 1e-4
SEARCH_DIRECTION = 1e-3  # moves above which CG stays at SEARCH_RTOL (its own accuracy)
# c as a share of 1 / diag(T diag(K)^-1 T'): with the whole of it, a patch whose slip reversed
# jumped to slip the other way and back (stick-slip-3d, mixed P1: never settled); at 1e-2 and
# 1e-4 it settles in 14 and 19 steps (Nitsche: 19 and 29; 16 with the whole)
COUPLING = 1e-2


@dataclass(frozen=True)
class FrictionSets:
    """The state of one step: normal rows in contact, nodes that stick, slip directions."""

    normal: np.ndarray     # (m,) bool
    stick: np.ndarray      # (nodes,) bool
    direction: np.ndarray  # (nodes, block) unit vectors where a node slips
    # kappa per node: the slip law's linearisation across the direction (0 where none)
    stiffness: np.ndarray | None = None


def first_sets(qp: ContactQP, previous: QPSolution | None,
               warm_start: np.ndarray | None) -> FrictionSets:
    """The previous step's answer's sets (a Coulomb step), else the warm start's contact zone
    (or the rows the undeformed body violates) with every node sticking."""
    nodes, block = qp.friction.bound.size, qp.friction.block
    if previous is not None and previous.tangential is not None:
        tangential = previous.tangential.reshape(nodes, block)
        size = np.linalg.norm(tangential, axis=1)
        slips = size >= qp.friction.bound * (1 - WEAKLY_ACTIVE)
        return FrictionSets(previous.multipliers > 0, ~slips,
                            tangential / np.where(size > 0, size, 1.0)[:, None])
    normal = np.asarray(warm_start) > 0 if warm_start is not None else -qp.G > 0
    return FrictionSets(normal, np.ones(nodes, dtype=bool), np.zeros((nodes, block)))


def coupling(qp: ContactQP, K: sparse.csr_matrix) -> np.ndarray:
    """c per friction node: 1 / the mean of diag(T diag(K)^-1 T') over its rows, a force per
    length as S^-1 scales (per node, because rows of different kinds, nodal values or
    integrals over patches, differ in scale by orders)."""
    T = qp.friction.T
    diagonal = np.asarray(T.multiply(T) @ (1.0 / K.diagonal())).ravel()
    per_node = diagonal.reshape(-1, qp.friction.block).mean(axis=1)
    return COUPLING / np.maximum(per_node, np.finfo(float).tiny)


def step_rows(qp: ContactQP, sets: FrictionSets):
    """(C_A, its right-hand side, the rows of T that stick, the slip force per row of T at
    zero slip, the slip law's stiffness per pair of rows of T as a sparse block matrix)."""
    friction, block = qp.friction, qp.friction.block
    nodes = friction.bound.size
    stick_rows = (block * np.flatnonzero(sets.stick)[:, None] + np.arange(block)).ravel()
    shift = np.zeros(friction.T.shape[0]) if friction.shift is None else friction.shift
    force = (friction.bound[:, None] * sets.direction * ~sets.stick[:, None]).ravel()
    kappa = np.zeros(nodes) if sets.stiffness is None else sets.stiffness * ~sets.stick
    across = (np.eye(block)[None] - np.einsum("ni,nj->nij", sets.direction, sets.direction))
    springs = sparse.bsr_matrix((kappa[:, None, None] * across, np.arange(nodes),
                                 np.arange(nodes + 1)), shape=(nodes * block,) * 2).tocsr()
    force = force - springs @ shift
    C_A = sparse.vstack([qp.B[np.flatnonzero(sets.normal)], friction.T[stick_rows]],
                        format="csr")
    return (C_A, np.concatenate([qp.G[sets.normal], shift[stick_rows]]), stick_rows, force,
            springs)


def next_sets(qp: ContactQP, sets: FrictionSets, u: np.ndarray, lam_n: np.ndarray,
              lam_t: np.ndarray, c: np.ndarray) -> tuple[FrictionSets, int, float]:
    """(the next sets, how many rows and nodes changed, the largest move of a direction)."""
    friction = qp.friction
    nodes, block, bound = friction.bound.size, friction.block, friction.bound
    normal = next_rows(qp, sets.normal, u, lam_n)
    z = lam_t.reshape(nodes, block) + c[:, None] * friction.slip(u).reshape(nodes, block)
    size = np.linalg.norm(z, axis=1)
    zero = WEAKLY_ACTIVE * max(bound.max(initial=0.0), np.abs(lam_t).max(initial=0.0))
    # either way a margin of the solve's accuracy: a node with |lambda_t| = b and no slip
    # satisfies both laws, and keeps the one it has
    stick = np.where(sets.stick, size <= bound + zero, size < bound - zero) & (bound > 0)
    direction = np.where(stick[:, None], sets.direction,
                         z / np.where(size > 0, size, 1.0)[:, None])
    slipping = ~stick & ~sets.stick & (bound > 0)
    moved = float(np.abs(direction - sets.direction)[slipping].max(initial=0.0))
    changed = int((normal != sets.normal).sum() + (stick != sets.stick).sum())
    ratio = np.where(stick | (size <= 0), 0.0, bound / np.where(size > 0, size, 1.0))
    stiffness = c * ratio / np.maximum(1.0 - ratio, np.finfo(float).eps)
    return FrictionSets(normal, stick, direction, stiffness), changed, moved


def solve_projected_tresca(qp: ContactQP, precondition, previous: QPSolution | None,
                           warm_start: np.ndarray | None, max_iter: int) -> QPSolution:
    """One Tresca problem (module docstring) from ``previous`` (a Coulomb step's last answer,
    whose u starts CG too) or ``warm_start``; ``precondition`` a multigrid cycle of qp.K."""
    start = time.perf_counter()
    K = sparse.csr_matrix(qp.K)
    c, sets = coupling(qp, K), first_sets(qp, previous, warm_start)
    u = np.zeros(qp.n) if previous is None or previous.u is None else previous.u
    counts, changes, rtol = [], [], SEARCH_RTOL
    lam_n, lam_t = np.zeros(qp.m), np.zeros(qp.friction.T.shape[0])

    def answer(status, reason, iterations):
        diagnostics = SolverDiagnostics(active_set_changes=tuple(changes),
                                        krylov_iterations=tuple(counts))
        return QPSolution(u if status == STATUS_OK else None, lam_n, status, reason,
                          iterations, time.perf_counter() - start, FAST_SOLVER, "amg",
                          diagnostics, tangential=lam_t)

    for iteration in range(1, max_iter + 1):
        C_A, rhs, stick_rows, force, springs = step_rows(qp, sets)
        try:
            project, particular, multipliers = projection(C_A)
        except RuntimeError:  # dependent rows: C_A C_A' singular
            return answer(STATUS_FAILED, SINGULAR, iterations=iteration)
        T = qp.friction.T
        F, J = qp.F - T.T @ force, (K + T.T @ springs @ T).tocsr()
        try:
            u, _ = projected_cg(J, precondition, project, F, project(u) + particular(rhs),
                                rtol, counts)
        except FactorisationError as error:
            return answer(STATUS_FAILED, str(error), iteration)
        lam_A = multipliers(F - J @ u)
        lam_n = np.zeros(qp.m)
        lam_n[sets.normal] = lam_A[:int(sets.normal.sum())]
        lam_t = force + springs @ (T @ u)
        lam_t[stick_rows] = lam_A[int(sets.normal.sum()):]
        new, changed, moved = next_sets(qp, sets, u, lam_n, lam_t, c)
        changes.append(changed)
        if changed == 0 and moved <= DIRECTION_TOLERANCE and rtol == RTOL:
            lam_n[sets.normal] = np.maximum(lam_n[sets.normal], 0.0)
            return answer(STATUS_OK, "", iteration)
        if changed == 0 and moved <= SEARCH_DIRECTION:
            rtol = RTOL
        sets = new
    return answer(STATUS_FAILED, f"friction sets or slip directions still changing after "
                                 f"{max_iter} iterations", max_iter)


def split_preconditioner(qp: ContactQP, backend: str):
    """The multigrid cycle of qp.K, as ``factorise`` builds it. A slack QP's K is the
    stiffness beside a diagonal block (the slacks' weights) and its rigid-body modes cover the
    stiffness only: the cycle then acts on the stiffness and the diagonal is inverted exactly."""
    K = sparse.csr_matrix(qp.K)
    modes = qp.near_null
    if modes is None or modes.shape[0] >= qp.n:
        return factorise(K, backend, modes).preconditioner.matvec
    k = modes.shape[0]
    rest = K[k:]
    if np.any(np.diff(rest.indptr) != 1) or np.any(rest.indices != np.arange(k, qp.n)):
        return factorise(K, backend, None).preconditioner.matvec
    cycle = factorise(K[:k, :k], backend, modes).preconditioner.matvec
    inverse = 1.0 / rest.diagonal(k)

    def precondition(r):
        return np.concatenate([cycle(r[:k]), inverse * r[k:]])

    return precondition

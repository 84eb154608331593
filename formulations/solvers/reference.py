"""The reference QP solver: CVXPY with Clarabel (docs/theory.md, section 3).

The judge of correctness, not the workhorse. The problem is scaled before it is handed over, so
that Clarabel's absolute and relative tolerances mean the same thing on every mesh, for every
Young's modulus and every size of gap: u = d v with the displacement scale d (the largest mean
gap |G_i| / row_scale_i, or 1 if all gaps vanish), the objective divided by E d^2
(E = objective_scale, K ~ E) and each constraint row by row_scale (B ~ h). The multipliers of the
scaled problem mu give lambda = E d mu / row_scale.
"""

from __future__ import annotations

import time
import warnings
from dataclasses import replace

import cvxpy as cp
import numpy as np
from scipy import sparse

from formulations.base import STATUS_FAILED, STATUS_INACCURATE, STATUS_OK, ContactQP, QPSolution
from formulations.solvers.coulomb import coulomb_fixed_point, joined
from formulations.solvers.registry import REFERENCE_SOLVER, register_solver

# Clarabel's defaults are 1e-8. Measured on the paper scene (2e3..3e4 DOFs) against the exact
# active-set solution: tolerances 1e-9 leave relative differences of ~3e-7 (energy norm) and
# ~1.3e-6 (max lambda); 1e-10 leaves ~3e-9 and ~1.3e-8 at the same ~10-12 iterations. We use
# 1e-10 so that the reference is well inside the 1e-7 / 1e-6 agreement it judges.
CLARABEL_TOLERANCES = {"tol_gap_abs": 1e-10, "tol_gap_rel": 1e-10, "tol_feas": 1e-10,
                       "tol_ktratio": 1e-8}


# With friction the gap also carries the slip term b |T u|, and 1e-10 left ~2e-7 (energy norm)
# against the exact active-set answer on paper P2 (2e3 DOFs); 1e-12 leaves ~2e-9 and ~2e-8 in
# lambda_t (1e-14 stops short: optimal_inaccurate)
FRICTION_TOLERANCES = {"tol_gap_abs": 1e-12, "tol_gap_rel": 1e-12, "tol_feas": 1e-12}

# Coulomb's fixed point on reference steps stops at this relative change of the bound, or once
# the change no longer falls below the noise floor: the steps' own multipliers carry ~1e-8
# relative noise at the tolerances above (vi, stick-slip P2, settled at a change of 8e-8), the
# penalty's up to ~1e-5 (its multipliers carry u's error times 1/eps)
COULOMB_RTOL, COULOMB_NOISE_FLOOR = 1e-8, 1e-4


def no_contact_bound(qp: ContactQP) -> float:
    """The largest Coulomb bound that is round-off: mu times a multiplier of 1e-9 in the scaled
    units (lambda = E d mu / row_scale; Clarabel at 1e-12 leaves ~1e-12 there where nothing
    touches)."""
    d = qp.gap_scale if 0 < qp.gap_scale < np.inf else 1.0
    return 1e-9 * qp.friction.coefficient * qp.objective_scale * d / float(qp.row_scale.min())


@register_solver(REFERENCE_SOLVER, "CVXPY + Clarabel interior point (the judge of correctness)")
def solve_reference(qp: ContactQP, warm_start=None, backend=None,
                    **clarabel_options) -> QPSolution:
    """Solve ``qp`` with Clarabel; ``warm_start`` and ``backend`` are accepted for the common
    solver interface and ignored (an interior-point method gains little from a warm start, and
    Clarabel brings its own sparse LDL'). Coulomb friction: a fixed point of such solves
    (``coulomb``)."""
    if qp.friction is not None and qp.friction.coulomb:
        return coulomb_fixed_point(qp, lambda step, _: solve_reference(step, **clarabel_options),
                                   COULOMB_RTOL, COULOMB_NOISE_FLOOR, zero=no_contact_bound(qp))
    if qp.friction is not None and not clarabel_options:
        answer = solve_reference(qp, **FRICTION_TOLERANCES)
        if answer.status == STATUS_OK:
            return answer
        # the tighter tolerances stalled (inaccurate) or broke down (failed: seen with the
        # cones of 3D friction on paper-3d)
        retry = solve_reference(qp, **CLARABEL_TOLERANCES)
        return replace(retry, reason=joined(retry.reason, f"{answer.status} at the friction "
                                             "tolerances 1e-12, answered at 1e-10"),
                       solve_time=answer.solve_time + retry.solve_time)
    settings = {**CLARABEL_TOLERANCES, **clarabel_options}
    d = qp.gap_scale if 0 < qp.gap_scale < np.inf else 1.0
    K = (qp.K / qp.objective_scale).tocsc()
    F = qp.F / (qp.objective_scale * d)
    row = sparse.diags(1.0 / qp.row_scale)
    B, G = (row @ qp.B).tocsr(), qp.G / (qp.row_scale * d)

    u = cp.Variable(qp.n)
    objective = 0.5 * cp.quad_form(u, cp.psd_wrap(K)) - F @ u
    constraints = [B @ u <= G] if qp.m else []
    if qp.friction is not None:  # b |T u| = max over |lambda_t| <= b of lambda_t T u
        objective, slips = friction_term(qp, u, objective, d)
        constraints += slips
    problem = cp.Problem(cp.Minimize(objective), constraints)
    start = time.perf_counter()
    try:
        with warnings.catch_warnings():  # an inaccurate answer is reported in the status
            warnings.filterwarnings("ignore", message="Solution may be inaccurate")
            problem.solve(solver=cp.CLARABEL, **settings)
    except cp.SolverError as error:
        return QPSolution(None, None, STATUS_FAILED, f"Clarabel failed: {error}", 0,
                          time.perf_counter() - start, REFERENCE_SOLVER, "clarabel")
    elapsed = time.perf_counter() - start
    stats = problem.solver_stats
    iterations = int(stats.num_iters or 0) if stats is not None else 0
    if problem.status not in (cp.OPTIMAL, cp.OPTIMAL_INACCURATE) or u.value is None:
        return QPSolution(None, None, STATUS_FAILED, f"Clarabel status {problem.status!r}",
                          iterations, elapsed, REFERENCE_SOLVER, "clarabel")
    mu = np.asarray(constraints[0].dual_value if qp.m else np.zeros(0), dtype=float).ravel()
    tangential = None
    if qp.friction is not None:
        tangential = tangential_reactions(qp, constraints, d)
    status, reason = STATUS_OK, ""
    if problem.status == cp.OPTIMAL_INACCURATE:
        status, reason = STATUS_INACCURATE, "Clarabel stopped short of its tolerances " \
                                            "(status optimal_inaccurate)"
    return QPSolution(u=d * np.asarray(u.value, dtype=float),
                      multipliers=qp.objective_scale * d * mu / qp.row_scale,
                      status=status, reason=reason, iterations=iterations, solve_time=elapsed,
                      solver=REFERENCE_SOLVER, backend="clarabel", tangential=tangential)


def friction_term(qp: ContactQP, u: cp.Variable, objective, d: float):
    """The Tresca term sum_i b_i |T_i u - w_i| in the scaled units (u = d v, objective / (E d^2),
    each row of T divided by its node's B row's ``row_scale``, r): a slip variable
    z_i >= |T_i v / r_i - w_i / (r_i d)| per node, costed (b r / (E d)) z; in 2D two one-sided
    rows whose multipliers are the tangential reactions (times r / (E d)), in 3D a second-order
    cone per node (``tangential_reactions``)."""
    friction = qp.friction
    nodes = friction.bound.size
    if friction.block not in (1, 2):
        raise ValueError(f"friction with {friction.block} tangential directions per node: "
                         "the reference has the 2D and 3D forms only")
    z = cp.Variable(nodes)
    scale = qp.row_scale[:nodes]  # the points' normal rows come first in B
    weight = friction.bound * scale / (qp.objective_scale * d)
    row_scale = np.repeat(scale, friction.block)
    T = (sparse.diags(1.0 / row_scale) @ friction.T).tocsr()
    shift = (np.zeros(T.shape[0]) if friction.shift is None
             else friction.shift / (row_scale * d))
    slip = T @ u - shift
    if friction.block == 1:
        return objective + weight @ z, [slip - z <= 0, -slip - z <= 0]
    return objective + weight @ z, [cp.SOC(z, cp.reshape(slip, (nodes, 2), order="C"),
                                           axis=1)]


def tangential_reactions(qp: ContactQP, constraints: list, d: float) -> np.ndarray:
    """lambda_t in force units from the friction constraints' multipliers: in 2D the two
    one-sided rows' difference, in 3D minus the cone's vector part (Clarabel's dual of
    |x| <= z pairs x with -lambda_t)."""
    friction = qp.friction
    scale = np.repeat(qp.row_scale[:friction.bound.size], friction.block)
    if friction.block == 1:
        plus, minus = (np.asarray(c.dual_value, dtype=float) for c in constraints[-2:])
        values = plus - minus
    else:
        values = -np.asarray(constraints[-1].dual_value[1], dtype=float).ravel()
    return qp.objective_scale * d * values / scale

"""KKT residuals of ``min 1/2 u'Ku - F'u s.t. Bu <= G`` computed from the returned arrays.

We never trust a solver's own claim of optimality (qpsolvers' idea): every residual is computed
here from u and lambda, each relative to a stated scale:

* ``violation``: max_i (Bu - G)_i^+ / row_scale_i (a mean penetration, a length) relative to
  the displacement scale max(max |u|, max |G_i / row_scale_i|);
* ``dual_violation``: max(-lambda)^+ relative to max |lambda| (the raw multipliers, before any
  clipping to lambda >= 0);
* ``complementarity``: |lambda'(Bu - G)| relative to the energy scale
  max(u'Ku, objective_scale * displacement_scale^2);
* ``stationarity``: ||Ku - F + B'lambda||_2 relative to the force scale
  max(||Ku||, ||F||, ||B'lambda||, max diag(K) * displacement_scale).

The floors built from the displacement scale keep the residuals meaningful when the solution
is (nearly) zero, e.g. when nothing touches; a scale that still vanishes is replaced by 1.
"""

from __future__ import annotations

import numpy as np

from formulations.base import (
    STATUS_FAILED,
    STATUS_INACCURATE,
    STATUS_OK,
    ContactQP,
    QPSolution,
    Residuals,
)

# A converged reference solve (Clarabel, tolerances 1e-10) gives residuals around 1e-13..1e-10
# relative, the active-set solver round-off; a solution worse than this is not reported "ok".
RESIDUAL_TOLERANCE = 1e-6


def _scale(*values: float) -> float:
    s = max(float(v) for v in values)
    return s if s > 0 and np.isfinite(s) else 1.0


def qp_residuals(qp: ContactQP, u: np.ndarray, multipliers: np.ndarray,
                 tangential: np.ndarray | None = None) -> Residuals:
    """The four residuals of the module docstring; with friction (``qp.friction``) they also
    judge the tangential reactions ``tangential`` (``friction_terms``)."""
    Ku = qp.K @ u
    gap = qp.B @ u - qp.G
    lam = np.maximum(multipliers, 0.0)
    BTl = qp.B.T @ lam
    u_scale = _scale(np.abs(u).max(initial=0.0), qp.gap_scale)
    energy_scale = _scale(u @ Ku, qp.objective_scale * u_scale**2)
    bound_excess, slip_gap = 0.0, 0.0
    if qp.friction is not None:
        tangential = np.zeros(qp.friction.T.shape[0]) if tangential is None else tangential
        BTl = BTl + qp.friction.T.T @ tangential
        bound_excess, slip_gap = friction_terms(qp, u, lam, tangential)
    return Residuals(
        violation=float(np.maximum(gap / qp.row_scale, 0.0).max(initial=0.0) / u_scale),
        dual_violation=max(float(np.maximum(-multipliers, 0.0).max(initial=0.0)
                                 / _scale(np.abs(multipliers).max(initial=0.0))), bound_excess),
        complementarity=float((abs(lam @ gap) + slip_gap) / energy_scale),
        stationarity=float(np.linalg.norm(Ku - qp.F + BTl)
                           / _scale(np.linalg.norm(Ku), np.linalg.norm(qp.F), np.linalg.norm(BTl),
                                    np.abs(qp.K.diagonal()).max(initial=0.0) * u_scale)),
    )


def friction_terms(qp: ContactQP, u: np.ndarray, lam: np.ndarray,
                   tangential: np.ndarray) -> tuple[float, float]:
    """The friction law's residuals (docs/theory.md, 17.2): max_i (|lambda_t,i| - b_i)^+
    relative to max(max b, max |lambda_t|) (a dual violation), and
    |sum_i b_i |T_i u| - lambda_t,i . T_i u| (a complementarity gap: zero exactly when each
    node sticks, T_i u = 0, or slips with lambda_t,i = b_i T_i u / |T_i u|; an energy)."""
    friction = qp.friction
    bound = friction.bounds(lam)
    size = friction.node_norms(tangential)
    excess = np.maximum(size - bound, 0.0).max(initial=0.0)
    excess /= _scale(bound.max(initial=0.0), size.max(initial=0.0))
    slip = friction.slip(u)
    gap = abs(bound @ friction.node_norms(slip) - tangential @ slip)
    return float(excess), float(gap)


def final_status(solution: QPSolution, residuals: Residuals | None) -> tuple[str, str]:
    """Final (status, reason): the solver's verdict, overruled by residuals that are too large."""
    if solution.status != STATUS_OK or residuals is None:
        return (solution.status if solution.status != STATUS_OK else STATUS_FAILED,
                solution.reason or "solver returned no solution")
    if not all(np.isfinite(v) for v in vars(residuals).values()):
        return STATUS_FAILED, "non-finite residual (NaN or inf in the returned arrays)"
    too_large = [f"{k}={v:.2e}" for k, v in vars(residuals).items() if v > RESIDUAL_TOLERANCE]
    if too_large:
        return STATUS_INACCURATE, (f"residuals above {RESIDUAL_TOLERANCE:g}: "
                                   + ", ".join(too_large))
    return STATUS_OK, ""


# A constraint counts as active when it is tight, (Bu - G)_i / row_scale_i >= -ACTIVE_FRACTION *
# displacement scale, and its multiplier exceeds ACTIVE_FRACTION * max lambda. Interior-point
# solutions leave slacks and inactive multipliers around 1e-9 relative; active-set ones at 0.
ACTIVE_FRACTION = 1e-6


def count_active(qp: ContactQP, u: np.ndarray, multipliers: np.ndarray) -> int:
    """Number of active contact constraints (tight, with a positive multiplier)."""
    if qp.m == 0 or not (np.isfinite(multipliers).all() and np.isfinite(u).all()):
        return 0
    u_scale = _scale(np.abs(u).max(initial=0.0), qp.gap_scale)
    tight = (qp.B @ u - qp.G) / qp.row_scale >= -ACTIVE_FRACTION * u_scale
    loaded = multipliers > ACTIVE_FRACTION * max(multipliers.max(), 0.0)
    return int((tight & loaded).sum())

"""Friction in the penalty method: the regularised friction law (docs/theory.md, 17.2).

With the penalty's eps on each facet, the tangential traction at a quadrature point is
lambda_t = P_[-s, s]((u_t - w) / eps) (w: the obstacle's slide): a stick zone softened to
|u_t - w| <= eps s, and the exact bound where it slips. Its energy is the Huber function
int min_r (r^2 / (2 eps) + s |u_t - w - r|) ds. The QP has one normal slack q_q and one
tangential slack r_q per point, both costed 1/2 D_q (.)^2 (D_q = w_q |e| / eps_e):

    min 1/2 u'Ku - F'u + 1/2 sum_q D_q (q_q^2 + r_q^2) + sum_q b_q |u_t(x_q) - w - r_q|
    s.t. u_n(x_q) - q_q <= g(x_q),

with q_q free (its minimum is (u_n - g)_+: the frictionless slack QP's second row q_q >= 0 is
not needed, and without it the rows stay independent where a P1 trace has fewer nodes than
points) and b_q = w_q |e| s(x_q) (Tresca) or mu times the multiplier of the point's normal row,
which is the penalty pressure times w_q |e| (Coulomb). The fast solver is the frictional active
set on that QP (``formulations.solvers.friction``), and the reference takes the same QP.
"""

from __future__ import annotations

import numpy as np
from scipy import sparse

from formulations.base import ContactQP, FrictionState
from formulations.friction.slack import (
    contact_tangents,
    shear_vectors,
    slack_friction_qp,
    tangential_rows,
)
from formulations.friction.state import friction_state


def penalty_friction_qp(scene, elasticity, P: sparse.csr_matrix, gap: np.ndarray,
                        weights: np.ndarray, trace, t: np.ndarray,
                        row_length: np.ndarray) -> ContactQP:
    """The QP of the module docstring (``formulations.friction.slack`` with R the tangential
    displacement at the points ``t``): unknowns u, the normal slacks, the tangential slacks
    (both weighted by ``weights``, D); P the normal rows at the points."""
    return slack_friction_qp(scene, elasticity.K_free, elasticity.F_free, P,
                             tangential_rows(elasticity, trace, t), gap, weights, row_length,
                             trace.points(t), contact_tangents(trace),
                             near_null=elasticity.rigid_modes)


def penalty_friction_state(qp: ContactQP, x: np.ndarray, normal: np.ndarray,
                           tangential: np.ndarray | None, trace, t: np.ndarray,
                           row_length: np.ndarray) -> FrictionState:
    """The points' states and sigma_t,h along the facets: the interpolant of the points'
    tractions -lambda_t,q / (w_q |e|) (the penalty pressure's interpolation; in 3D per
    tangential component, then the vector sum_k sigma_k t_k)."""
    friction, ns = qp.friction, row_length.size
    if tangential is None:  # a failed solve: NaN, never a silent zero
        tangential = np.full(friction.block * ns, np.nan)
    at_points = (-tangential / np.repeat(row_length, friction.block)).reshape(
        trace.size, -1, friction.block)  # (facet, point, tangent)
    tangents = contact_tangents(trace)

    def traction(tt):
        values = np.einsum("fqk,qt->ftk", at_points,
                           trace.interpolation(t, np.asarray(tt, dtype=float)))
        return values[..., 0] if friction.block == 1 else shear_vectors(values, tangents)

    return friction_state(friction, x, normal[:ns], tangential, 1.0 / row_length,
                          trace.row_coordinates(t), traction)

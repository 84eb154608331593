"""``penalty``: the primal penalty method (docs/theory.md, section 3).

Minimise E(v) + 1/(2 eps) int_{Gamma_C} (v_n - g)_+^2 ds over P1 displacements, with
eps = eps_0 h_e / E on each contact facet e (h_e its length, E Young's modulus). The factor
1/E makes eps_0 dimensionless: the same eps_0 means the same relative penetration for E = 1 and
E = 70000. The discrete pressure is lambda_h = (u_hn - g)_+ / eps (a formula, not a multiplier).

Default eps_0 = 1e-3: the penalty's consistency error in the energy norm is about
sqrt(eps) ||lambda||_{0,Gamma_C} ~ sqrt(eps_0 h) relative, i.e. 3 % of sqrt(h) -- well below the
O(h^1/2) discretisation error of every formulation here -- while the penalty block stays within a
factor 1/eps_0 = 1e3 of the stiffness (conditioning). Smaller eps_0 is a hard case
(``bench.hard.cases.penalty_eps``).

The gap is the P1 interpolant g_h of g on the contact facets (as the nodal constraints of
``vi`` see it): with the exact g, u_hn - g (linear minus curved) penetrates by O(h^2 g'') between
any quadrature points, and lambda_h = (u_hn - g)_+ / eps would be O(E h g'' / eps_0) there,
i.e. garbage for small eps_0 (measured: 4e5 against a true peak of 2e4 on the paper scene). The
geometric error g - g_h is left to the estimators' contact terms, which use the exact g.

Self-check: at the minimiser the pressure (u_hn - g_h)_+ / eps at a Gauss point equals the
multiplier of its row per unit length; the two are compared on every solve and a mismatch above
``PRESSURE_CONSISTENCY`` turns status "ok" into "inaccurate" (the formula divides u's error by
eps, so an interior-point answer that is fine in energy can carry a wrong pressure).

The integral uses Gauss points per facet. As a QP (so that the reference and the active-set
solvers apply unchanged), (x)_+^2 = min {s^2 : s >= x, s >= 0} gives slack unknowns s_q, one per
quadrature point:

    min 1/2 u'Ku - F'u + 1/2 sum_q D_q s_q^2   s.t.  u_n(x_q) - s_q <= g(x_q),  -s_q <= 0,

with D_q = w_q h_e / eps_e = E w_q / eps_0 (Gauss weights w_q on [0, 1]); the reference
solver takes this QP. The fast solver takes the penalised equation itself,
K u + P' D (P u - g)_+ = F, a ``SemismoothSystem`` without the sigma_nn term (gamma = 1/eps):
semismooth Newton condensed onto the Gauss points, one unknown each instead of the QP's two
rows and a slack (Hintermueller, Ito, Kunisch 2003: the same iteration as the primal-dual
active set method on the QP).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import sparse
from skfem import MeshTri

from formulations.base import (
    STATUS_INACCURATE,
    STATUS_OK,
    DiscreteSolution,
    QPSolution,
    Residuals,
    slack_qp,
)
from formulations.cells.evaluation import drop_roundoff, normal_trace_matrix
from formulations.contact import contact_trace, gap_interpolant
from formulations.discretisation import Discretisation, discrete_solution
from formulations.elasticity import assemble_elasticity, check_order
from formulations.friction.penalty import penalty_friction_qp, penalty_friction_state
from formulations.registry import register_formulation
from formulations.semismooth import SemismoothSystem
from scenes import Scene
from scenes.base import is_number

DEFAULT_EPSILON_0 = 1e-3
# Gauss points per contact facet: p + 1, exact for the (degree 2p) penalty integrand where the
# penetration keeps its sign on a facet
# the largest relative mismatch between the two readings of the pressure (see recover) for
# status "ok". Measured on the paper scene: ~1e-12 for the active-set solver at the default
# eps_0 (growing like 1/eps_0 to 2.5e-3 at 1e-12); for the reference 6.5e-6 (uniform, 2112
# DOFs) to 4.3e-4 (adaptive, 1002 DOFs) at the default, 1e-2 at 1e-6 and O(1) once it loses the
# penetration (eps_0 <= 1e-8). 0.1 % keeps the usable answers and flags the wrong ones.
PRESSURE_CONSISTENCY = 1e-3


@dataclass(frozen=True, eq=False)
class PenaltyDetails:
    """The penalty's own numbers: eps_0, eps per contact facet and the slacks of the QP."""

    epsilon_0: float
    epsilon: np.ndarray
    slacks: np.ndarray


def pressure_mismatch(penetration: np.ndarray, epsilon: np.ndarray, multipliers: np.ndarray,
                      row_length: np.ndarray, floor: float) -> float:
    """Max difference at the Gauss points between the formula's pressure
    penetration_+ / eps and the multiplier of each row u_n - s <= g per unit length
    (``row_length`` = Gauss weight x facet length; equal at an exact minimiser: D s = mu),
    relative to the larger pressure, or to ``floor`` = E max|g| / |Gamma_C| when both vanish.
    The formula divides u's error by eps, the multiplier does not: a large mismatch means u is
    too inaccurate for this eps."""
    if not np.isfinite(multipliers).all() or not np.isfinite(penetration).all():
        return float("nan")
    formula = np.maximum(penetration, 0.0) / epsilon
    from_multiplier = np.maximum(multipliers, 0.0) / row_length
    scale = max(formula.max(initial=0.0), from_multiplier.max(initial=0.0), floor)
    return float(np.abs(formula - from_multiplier).max(initial=0.0) / scale) if scale else 0.0


def penalty_pressure(elasticity, trace, gap_h, epsilon: np.ndarray, u_free: np.ndarray,
                     penetration_at_points: np.ndarray, t: np.ndarray):
    """lambda_h(t) on every contact facet (module docstring): (u_hn - g_h)_+ / eps for P1; for
    p >= 2 the degree-p interpolant of its values at the quadrature points ``t`` (p + 1 Gauss
    points in 2D, the 6 points of the degree-4 rule on triangles), clipped to [0, the largest
    of the facet's values] (the same polynomial where a facet penetrates throughout and the
    interpolant stays below its largest sample)."""
    if elasticity.order == 1:
        u_full = elasticity.expand(u_free)

        def formula(tt):
            tt = np.asarray(tt, dtype=float)
            u_n = (normal_trace_matrix(elasticity.basis, trace, tt) @ u_full).reshape(
                trace.size, -1)
            return np.maximum(u_n - gap_h(tt), 0.0) / epsilon[:, None]

        return formula
    at_points = penetration_at_points / epsilon[:, None]  # (n_facets, p + 1)
    # a polynomial through interior points overshoots towards the facet's corners where the
    # samples have a kink (the zone's edge crosses the facet): hertz-3d, P2, 38 538 adaptive
    # DOFs, unbounded: peak 3.25 x Hertz's. Between its samples lambda_h stays within them
    largest = np.maximum(at_points.max(axis=1, keepdims=True), 0.0)

    def interpolant(tt):
        values = at_points @ trace.interpolation(t, np.asarray(tt, dtype=float))
        return np.clip(values, 0.0, largest)

    return interpolant


def checked_epsilon(epsilon_0: float) -> float:
    if not (is_number(epsilon_0) and np.isfinite(epsilon_0) and epsilon_0 > 0):
        raise ValueError(f"epsilon_0={epsilon_0!r} is not a finite number > 0")
    return epsilon_0


def penalty_problems(scene, elasticity, trace, t: np.ndarray, P, gap: np.ndarray,
                     weights: np.ndarray, row_length: np.ndarray, row_epsilon: np.ndarray):
    """(qp, system): the slack QP and the penalised equation (module docstring); with friction
    the QP of ``penalty_friction`` and no system."""
    if scene.friction.active:  # the regularised friction law on its own QP
        return penalty_friction_qp(scene, elasticity, P, gap, weights, trace, t,
                                   row_length), None
    young = float(scene.material.young_modulus)
    system = SemismoothSystem(K=elasticity.K_free, F=elasticity.F_free,
                              S=sparse.csr_matrix((0, elasticity.free.size)), N=P, gap=gap,
                              weight=row_length, gamma=1.0 / row_epsilon, theta=0.0,
                              objective_scale=young, near_null=elasticity.rigid_modes)
    return slack_qp(elasticity.K_free, elasticity.F_free, P, gap, weights, young), system


@register_formulation("penalty", "primal penalty, eps = eps_0 h_e / (p^2 E) (eps_0 = 1e-3), "
                                 "lambda_h = (u_hn - g_h)_+ / eps; Tresca or Coulomb "
                                 "friction regularised with the same eps (2D and 3D)",
                      friction=(2, 3))
def discretise(scene: Scene, mesh: MeshTri, epsilon_0: float = DEFAULT_EPSILON_0,
               order: int = 1) -> Discretisation:
    epsilon_0, order = checked_epsilon(epsilon_0), check_order(order)  # before any assembly
    elasticity = assemble_elasticity(scene, mesh, order)
    trace = contact_trace(scene, mesh)
    young = float(scene.material.young_modulus)
    t, w = trace.rule(2 * order)  # 2D: the p + 1 Gauss points; 3D: 3 (P1) or 6 (P2) points
    nf, nq = trace.size, t.shape[-1]
    n = elasticity.free.size
    ns = nf * nq
    gap_h = gap_interpolant(scene, trace, order)
    gap = gap_h(t)
    P = elasticity.restrict(normal_trace_matrix(elasticity.basis, trace, t))
    # round-off of the functions that vanish on the facet, and normal components it lacks: not
    P = drop_roundoff(P)  # columns of the Schur set
    epsilon = epsilon_0 * trace.diameter / (order**2 * young)
    # per Gauss point: eps, and Gauss weight x facet measure (its share of Gamma_C)
    row_epsilon, row_length = np.repeat(epsilon, nq), np.tile(w, nf) * np.repeat(trace.measure,
                                                                                 nq)
    # D_q = w_q |e| / eps_e = p^2 E w_q / eps_0 (|e| / h_e: 1 in 2D, exactly)
    weights = (order**2 * young / epsilon_0 * np.tile(w, nf)
               * np.repeat(trace.measure / trace.diameter, nq))
    qp, system = penalty_problems(scene, elasticity, trace, t, P, gap.ravel(), weights,
                                  row_length, row_epsilon)
    pressure_floor = young * np.abs(gap).max(initial=0.0) / trace.measure.sum()

    def recover(answer: QPSolution, residuals: Residuals, status: str,
                reason: str) -> DiscreteSolution:
        u_free = answer.u[:n]
        penetration_at_points = P @ u_free - gap.ravel()
        if answer.u.size > n:  # the QP: u, then the slacks; multipliers per row
            slacks, row_multipliers = answer.u[n:n + ns], answer.multipliers[:ns]
        else:  # the system: u alone; its multipliers are the pressures at the Gauss points
            slacks = np.maximum(penetration_at_points, 0.0)
            row_multipliers = answer.multipliers * row_length
        mismatch = pressure_mismatch(penetration_at_points, row_epsilon, row_multipliers,
                                     row_length, pressure_floor)
        if status == STATUS_OK and mismatch > PRESSURE_CONSISTENCY:
            status, reason = STATUS_INACCURATE, (
                f"penalty pressure (u_hn - g_h)_+/eps disagrees with the QP multipliers by "
                f"{mismatch:.1e} (relative): u is not accurate enough for eps_0={epsilon_0:g}")
        pressure = penalty_pressure(elasticity, trace, gap_h, epsilon, u_free,
                                    np.maximum(penetration_at_points, 0.0).reshape(nf, nq), t)
        penetrating = int((penetration_at_points > 0).sum())
        return discrete_solution(
            "penalty", elasticity, trace, answer, residuals, status, reason, u_free=u_free,
            pressure=pressure, multiplier_breaks=trace.facet_breaks(),
            active_constraints=penetrating,
            pressure_mismatch=mismatch,
            details=PenaltyDetails(epsilon_0=epsilon_0, epsilon=epsilon, slacks=slacks),
            friction=None if qp.friction is None else penalty_friction_state(
                qp, answer.u, answer.multipliers, answer.tangential, trace, t, row_length))

    # warm starts: the previous pressure at the Gauss points (the system's unknowns)
    return Discretisation(formulation="penalty", elasticity=elasticity, trace=trace, qp=qp,
                          recover=recover,
                          row_coordinate=trace.row_coordinates(t), system=system,
                          qp_is_slack_form=qp.friction is None)

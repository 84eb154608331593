"""``nitsche``: Nitsche's method for unilateral contact (Chouly, Hild, Renard; docs/theory.md,
section 12).

With the outer normal n, the constraint u_n <= g, sigma_nn = n . sigma n, the Nitsche pressure
P_gamma(u) = sigma_nn(u) + gamma (g - u_n) and [x]_- = min(x, 0), find u_h in V_h with

    a(u_h, v) - theta/gamma (sigma_nn(u_h), sigma_nn(v))_C
        + 1/gamma ([P_gamma(u_h)]_-, theta sigma_nn(v) - gamma v_n)_C = L(v)   for all v,

gamma = gamma_0 E / h_F on each contact facet F (GetFEM writes gamma_0 h for the inverse,
1/gamma). The discrete pressure is lambda_h = -[P_gamma(u_h)]_- >= 0, a function of u_h on
every point of Gamma_C. theta = 1 (symmetric, the default), 0 or -1 (skew-symmetric) is the
option ``theta`` (any value in [-1, 1] is accepted); gamma_0 the option ``gamma_0``.

The gap is the P_p interpolant g_h of g on the contact facets (as for the penalty): with the
exact g, P_gamma would carry gamma (g - g_h) ~ gamma_0 E h g'' between quadrature points, and
lambda_h there would be off by that (measured on hertz at 65 792 DOFs: 91 at facet midpoints
where the Gauss points give 27). The geometric error g - g_h is left to the estimators' contact
terms, which use the exact g. The contact integrals use p + 1 Gauss points per facet (exact
for the smooth parts, degree 2p; the kink of [.]_- inside a facet costs O(h^2p+2) per facet,
far below the discretisation error). The problem is a ``SemismoothSystem``; for theta = 1 it
is also the optimality condition of the convex functional

    J(u) = 1/2 a(u, u) - L(u) - 1/(2 gamma) ||sigma_nn(u)||^2_C + 1/(2 gamma) ||[P_gamma(u)]_-||^2_C

(convex when gamma_0 is large enough, docs/theory.md 12.2), written as a QP with one slack per
Gauss point, [x]_-^2 = min {s^2 : s >= -x, s >= 0}, so that the reference solver can judge it.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from scipy import sparse
from skfem import MeshTri

from formulations.base import (
    ConsistencyTerm,
    ContactQP,
    DiscreteSolution,
    QPSolution,
    Residuals,
    slack_qp,
)
from formulations.cells.evaluation import evaluate_on_trace
from formulations.contact import contact_trace, gap_interpolant
from formulations.discretisation import Discretisation, discrete_solution
from formulations.elasticity import assemble_elasticity, check_order
from formulations.friction.nitsche import (
    nitsche_friction_qp,
    nitsche_friction_state,
    shear_residual,
)
from formulations.registry import register_formulation
from formulations.semismooth import SemismoothSystem
from scenes import Scene
from scenes.base import is_number

# gamma_0 of gamma = gamma_0 E / h_F: large enough for the symmetric variant to be coercive
# at every order here (docs/theory.md 12.2: a(v, v) - 1/gamma ||sigma_nn(v)||^2_C >= 0 needs
# gamma_0 >= 1.96 (P1), 6.28 (P2), 12.97 (P3) on paper (nu = 0.3) and 2.37, 7.57, 15.60 on
# free-boundary and hertz, mesh-independent), small enough to keep the contact block within a
# factor ~1e2 of the stiffness
DEFAULT_GAMMA_0 = 100.0


@dataclass(frozen=True, eq=False)
class NitscheDetails:
    """Nitsche's own numbers: its parameters and gamma per contact facet."""

    theta: float
    gamma_0: float
    gamma: np.ndarray


def convex_form(system: SemismoothSystem) -> ContactQP:
    """The theta = 1 system as a QP in (u, s') with s' = s / gamma a length (module
    docstring): min 1/2 u'(K - S'(W/gamma)S)u - F'u + 1/2 s'(W gamma)s' subject to
    N u - S u / gamma - s' <= g and -s' <= 0."""
    K = system.K - system.S.T @ sparse.diags(system.weight / system.gamma) @ system.S
    rows = system.N - sparse.diags(1.0 / system.gamma) @ system.S
    return slack_qp(K, system.F, rows, system.gap, system.weight * system.gamma,
                    system.objective_scale)


def check_options(theta, gamma_0) -> None:
    if not (is_number(theta) and np.isfinite(theta) and -1.0 <= theta <= 1.0):
        raise ValueError(f"theta={theta!r} is not a number in [-1, 1] (1: symmetric, "
                         "0, -1: skew-symmetric)")
    if not (is_number(gamma_0) and np.isfinite(gamma_0) and gamma_0 > 0):
        raise ValueError(f"gamma_0={gamma_0!r} is not a finite number > 0")


def pressure_function(gap_h, elasticity, trace, gamma_facet: np.ndarray, u_free: np.ndarray):
    """lambda_h(t) = -min(P_gamma(u_h), 0) at local coordinates t of every contact facet."""
    u = elasticity.expand(u_free)

    def pressure(t):
        t = np.asarray(t, dtype=float)
        nq = t.shape[-1]
        at = evaluate_on_trace(elasticity.basis, trace, t)
        normal = np.repeat(trace.normal, nq, axis=1)
        sigma = at.normal_stress_matrix(normal, elasticity.lame) @ u
        u_n = at.matrix(normal) @ u
        argument = sigma + np.repeat(gamma_facet, nq) * (gap_h(t).ravel() - u_n)
        return -np.minimum(argument, 0.0).reshape(trace.size, nq)

    return pressure


def nitsche_system(scene: Scene, elasticity, trace, gap_h, t: np.ndarray, w: np.ndarray,
                   gamma_facet: np.ndarray, theta: float) -> SemismoothSystem:
    """The discrete equation of the module docstring as a ``SemismoothSystem``."""
    nq = t.shape[-1]
    at = evaluate_on_trace(elasticity.basis, trace, t)
    normal = np.repeat(trace.normal, nq, axis=1)
    return SemismoothSystem(
        K=elasticity.K_free, F=elasticity.F_free,
        S=elasticity.restrict(at.normal_stress_matrix(normal, elasticity.lame)),
        N=elasticity.restrict(at.matrix(normal)),
        gap=gap_h(t).ravel(),
        weight=np.tile(w, trace.size) * np.repeat(trace.measure, nq),
        gamma=np.repeat(gamma_facet, nq), theta=float(theta),
        objective_scale=float(scene.material.young_modulus),
        near_null=elasticity.rigid_modes)


def consistency_term(system: SemismoothSystem, trace, u_free: np.ndarray, points: np.ndarray,
                     shear_residual=None) -> ConsistencyTerm | None:
    """(12.1)'s terms beyond the tractions lambda_h and sigma_t,h as a ``ConsistencyTerm``:
    q = theta/gamma ((sigma_nn(u_h) + lambda_h) n + the shear residual ``shear_residual(t)``
    under friction, ``formulations.friction.nitsche``) at the system's own points (``points``
    t on every contact facet; docs/theory.md 13.2, "Balance"); None for theta = 0, whose
    equation has none."""
    if system.theta == 0:
        return None
    nq = points.shape[-1]
    normal = np.repeat(trace.normal, nq, axis=1)
    residual = (system.S @ u_free + system.pressure(u_free)) * normal          # (d, n_f nq)
    if shear_residual is not None:
        residual = residual + shear_residual(points).reshape(residual.shape)
    return ConsistencyTerm(points=points, weights=system.weight,
                           vector=(system.theta / system.gamma * residual).reshape(
                               trace.dim, trace.size, nq))


def check_friction(scene: Scene, theta: float) -> None:
    if scene.friction.active and theta != 1:
        raise ValueError(f"theta={theta:g} with friction ({scene.friction.label}) is not "
                         "allowed: Nitsche's method models friction for theta = 1 only (the "
                         "optimality condition of a convex functional)")


@register_formulation("nitsche", "Nitsche's method, theta = 1 (symmetric, default), 0 or -1 "
                                 "(option theta), gamma = gamma_0 E / h_F (option gamma_0, "
                                 f"default {DEFAULT_GAMMA_0:g}), lambda_h = -[P_gamma(u_h)]_-; "
                                 "Tresca or Coulomb friction with theta = 1 (2D and 3D)",
                      friction=(2, 3), traits=("nitsche-contact",))
def discretise(scene: Scene, mesh: MeshTri, theta: float = 1.0,
               gamma_0: float = DEFAULT_GAMMA_0, order: int = 1) -> Discretisation:
    check_options(theta, gamma_0)
    check_friction(scene, theta)
    elasticity = assemble_elasticity(scene, mesh, check_order(order))
    trace = contact_trace(scene, mesh)
    t, w = trace.rule(2 * elasticity.order)  # 2D: the p + 1 Gauss points
    gamma_facet = gamma_0 * float(scene.material.young_modulus) / trace.diameter
    gap_h = gap_interpolant(scene, trace, elasticity.order)
    system = nitsche_system(scene, elasticity, trace, gap_h, t, w, gamma_facet, theta)
    n, s_points = system.n, trace.row_coordinates(t)
    details = NitscheDetails(theta=float(theta), gamma_0=float(gamma_0), gamma=gamma_facet)
    friction = (nitsche_friction_qp(scene, system, elasticity, trace, t)
                if scene.friction.active else None)

    def recover(answer: QPSolution, residuals: Residuals, status: str,
                reason: str) -> DiscreteSolution:
        u_free = answer.u[:n]  # the QP route carries one slack per Gauss point after u
        pressure_at_points = system.pressure(u_free)
        pressure = pressure_function(gap_h, elasticity, trace, gamma_facet, u_free)
        residual = (shear_residual(scene, elasticity, trace, gamma_facet, u_free, pressure)
                    if friction is not None else None)
        return discrete_solution(
            "nitsche", elasticity, trace, replace(answer, multipliers=pressure_at_points),
            residuals, status, reason, u_free=u_free, pressure=pressure,
            multiplier_breaks=trace.facet_breaks(),
            active_constraints=int((pressure_at_points > 0).sum()), details=details,
            consistency=consistency_term(system, trace, u_free, t, residual),
            friction=None if friction is None else nitsche_friction_state(
                scene, friction, answer, elasticity, trace, t, system.weight, gamma_facet,
                pressure))

    def transfer(previous: DiscreteSolution) -> np.ndarray:
        return previous.pressure_at(s_points)  # > 0 where the previous level pressed

    if friction is not None:  # the QP alone: the system has no friction law
        return Discretisation(formulation="nitsche", elasticity=elasticity, trace=trace,
                              qp=friction, recover=recover, row_coordinate=s_points)
    symmetric = theta == 1
    return Discretisation(
        formulation="nitsche", elasticity=elasticity, trace=trace,
        qp=convex_form(system) if symmetric else None, recover=recover,
        row_coordinate=s_points, transfer=transfer, system=system,
        qp_is_slack_form=True,
        no_qp="" if symmetric else f"theta={theta:g} is not the optimality condition of a "
                                   "convex functional (only theta = 1 is)")

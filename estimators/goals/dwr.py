"""``dwr``: the dual-weighted residual of a quantity of interest (docs/theory.md, 20.2-20.3):

    J(u, lambda) - J(u_h, lambda_h) ~ rho(z) + (pi, g - u_h.n)_{A_h},
    rho(v) = L(v) - a(u_h, v) - (lambda_h, v.n)_{Gamma_C},

with (z, pi) the dual problem's solution of order p + 1 (``estimators.goals.dual``). The local
indicators are rho(z - i_h z) split over the DOFs of order p + 1 (the Lagrange basis is a
partition of unity), each DOF's share divided among its elements, plus each constrained node's
contact term on its facet's element; i_h is the nodal interpolant of order p, which makes the
weights local (rho vanishes on the discrete space where lambda_h is the discrete equation's
own multiplier).
"""

from __future__ import annotations

import numpy as np

from estimators.goals.base import GoalEstimate, register_goal_estimator
from estimators.goals.dual import DualSolution, normal_rows, solve_dual
from estimators.quantities.base import weighted_pressure
from formulations.cells.evaluation import normal_trace_matrix
from formulations.cells.order_interpolation import interpolation_matrix


def no_dual_space(scene=None, family=None, order=None, quantity=None, **_) -> str | None:
    """Why the dual problem cannot be posed: the order p + 1 space is missing on ``family``
    (a ``CellFamily``: 3D P2, P3), or ``quantity`` has none."""
    if quantity is not None and quantity.why_no_dual is not None:
        return f"{quantity.name}: {quantity.why_no_dual}"
    why = None if family is None or order is None else family.why_no_element(order + 1)
    return None if why is None else f"dwr solves its dual problem with P{order + 1}: {why}"


def nodal_reactions(solution) -> np.ndarray | None:
    """The contact reactions of a nodal formulation (forces at the trace nodes of its order,
    ``details.reactions``), None where lambda_h is a function of its own."""
    return getattr(solution.details, "reactions", None)


def contact_load(solution, elasticity) -> np.ndarray:
    """The discrete contact traction on every basis function of ``elasticity``: (lambda_h,
    phi_i . n)_{Gamma_C}, or where the formulation's discrete equation has nodal reactions
    R_j (vi), sum_j R_j phi_i(x_j) . n_j: the traction the discrete equation holds with, so
    that rho vanishes on the discrete space and lambda_h lives on the contact nodes only."""
    trace, reactions = solution.trace, nodal_reactions(solution)
    if reactions is not None:
        nodes = trace.nodes(solution.elasticity.order)
        return normal_rows(elasticity, trace, nodes).T @ reactions
    t, w = trace.rule(trace.kink_degree)
    pressure = solution.pressure(t) * w[None, :] * trace.measure[:, None]
    return normal_trace_matrix(elasticity.basis, trace, t).T @ pressure.ravel()


def nodal_value_gap(solution, quantity) -> float:
    """(lambda_h^nodal - lambda_h, omega): what J takes from the nodal reactions (the
    traction ``contact_load`` uses) beyond what it takes from the reported lambda_h (vi's
    lumped pressure); 0 for the other formulations."""
    reactions = nodal_reactions(solution)
    if reactions is None or quantity.weight is None:
        return 0.0
    nodes = solution.trace.nodes(solution.elasticity.order)
    return float(reactions @ quantity.weight(nodes.points)
                 - weighted_pressure(solution, quantity.weight))


def element_shares(basis, values: np.ndarray) -> np.ndarray:
    """Per element, the sum of its DOFs' ``values`` each divided by its number of elements."""
    count = np.bincount(basis.element_dofs.ravel(), minlength=basis.N)
    share = values / np.maximum(count, 1)
    return share[basis.element_dofs].sum(axis=0)


@register_goal_estimator("dwr", "dual-weighted residual: the goal's dual problem at the "
                                "discrete contact set, solved with P(p+1); asymptotic, "
                                "signed", applies=no_dual_space)
def estimate(scene, solution, quantity, backend: str | None = None) -> GoalEstimate:
    if quantity.why_no_dual is not None:
        raise ValueError(f"goal={quantity.name!r} has no dual problem: {quantity.why_no_dual}")
    dual: DualSolution = solve_dual(scene, solution, quantity, backend)
    primal, plus = solution.elasticity, dual.elasticity
    up = interpolation_matrix(primal.basis, plus.basis)
    u_plus = up @ solution.u
    residual = plus.F - plus.K @ u_plus - contact_load(solution, plus)
    filtered = dual.z - up @ (interpolation_matrix(plus.basis, primal.basis) @ dual.z)
    gap = np.asarray(scene.gap(dual.points), dtype=float) - dual.normal_rows @ u_plus
    contact = dual.reaction * gap
    local = element_shares(plus.basis, residual * filtered)
    np.add.at(local, dual.elements, contact)
    residual_part = float(residual @ dual.z) + nodal_value_gap(solution, quantity)
    return GoalEstimate(estimator="dwr", quantity=quantity.name,
                        value=float(quantity.evaluate(solution)),
                        estimate=residual_part + float(contact.sum()),
                        residual_part=residual_part, contact_part=float(contact.sum()),
                        indicators=np.abs(local), dual_dofs=plus.ndofs, seconds=dual.seconds)

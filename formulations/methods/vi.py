"""``vi``: the primal variational inequality with nodal constraints (docs/theory.md, section 3).

Find u_h in the P1 space with u_h(x_i) . n_i <= g(x_i) at every node x_i of Gamma_C minimising
the energy: the QP min 1/2 u'Ku - F'u s.t. Bu <= G with one row per contact node,
B_i = n_i' (at the two DOFs of node i) and G_i = g(x_i). n_i is the length-weighted mean of the
outer normals of the facets at x_i (the facet normal on a straight Gamma_C).

The multiplier mu_i of row i is the nodal contact reaction (a force). The pressure is recovered
through the LUMPED boundary mass matrix, lambda_i = mu_i / int_{Gamma_C} phi_i ds, and
interpolated linearly along Gamma_C. Lumping keeps lambda_h >= 0 node by node (the consistent
mass matrix can turn non-negative reactions into negative pressures next to the contact-zone
end); both are exact for a constant pressure, and on uniform meshes for a linear one.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import partial

import numpy as np
from skfem import MeshTri

from formulations.base import ContactQP, DiscreteSolution, QPSolution, Residuals
from formulations.contact import contact_trace
from formulations.contact.boundary import conforming_nodes, tangent_frame
from formulations.discretisation import Discretisation, discrete_solution
from formulations.elasticity import assemble_elasticity, check_order
from formulations.friction.nodal import friction_rows, interleaved, nodal_friction
from formulations.kkt import count_active
from formulations.registry import register_formulation
from scenes import Scene


@dataclass(frozen=True, eq=False)
class NodalDetails:
    """The nodal VI's own arrays: contact reactions (forces), lambda_h at the contact nodes
    (reactions through the lumped boundary mass) and the contact nodes."""

    reactions: np.ndarray
    nodal_pressure: np.ndarray
    contact_nodes: np.ndarray


@register_formulation("vi", "primal variational inequality: nodal constraints "
                            "u_h(x_i).n_i <= g(x_i) at every Lagrange node of Gamma_C, "
                            "lambda_h from the nodal reactions; Tresca or Coulomb friction "
                            "on the same nodes (2D and 3D)", friction=(2, 3))
def discretise(scene: Scene, mesh: MeshTri, order: int = 1) -> Discretisation:
    elasticity = assemble_elasticity(scene, mesh, check_order(order))
    trace = contact_trace(scene, mesh)
    nodes = trace.nodes(elasticity.order)
    rows = partial(trace.node_rows, elasticity, nodes)
    # a node hanging on Gamma_C (3D hierarchies) is no constraint of its own
    conforming = conforming_nodes(elasticity, rows, nodes.weight.size)
    if conforming is not None and scene.friction.active:
        raise ValueError("friction with hanging nodes on Gamma_C is not built")
    kept = np.arange(nodes.weight.size) if conforming is None else conforming.kept
    B = rows()[kept]  # along the normals; with a direction per node, along it
    m = kept.size
    G = np.asarray(scene.gap(nodes.points), dtype=float)[kept]
    # rows of B are dimensionless (a normal), so the multipliers are forces; row_scale 1
    frame = tangent_frame(nodes.normal)
    friction = (friction_rows(scene, nodes, elasticity.restrict(
        interleaved([rows(t) for t in frame])), frame)
        if scene.friction.active else None)
    qp = ContactQP(K=elasticity.K_free, F=elasticity.F_free,
                   B=elasticity.restrict(B), G=G, row_scale=np.ones(m),
                   objective_scale=float(scene.material.young_modulus),
                   near_null=elasticity.rigid_modes, friction=friction)
    coordinate = np.asarray(scene.contact_coordinate(nodes.points), dtype=float)
    row_coordinate = coordinate[..., kept]

    def tangential_of(answer: QPSolution) -> np.ndarray:  # NaN where a solve failed
        if answer.tangential is not None:
            return answer.tangential
        return np.full(friction.T.shape[0], np.nan)

    def recover(answer: QPSolution, residuals: Residuals, status: str,
                reason: str) -> DiscreteSolution:
        reaction = np.zeros(nodes.weight.size)
        reaction[kept] = np.maximum(answer.multipliers, 0.0)
        lam = (trace.node_pressures(nodes, reaction) if conforming is None else conforming.S
               @ (reaction[kept] / conforming.weights(nodes.weight)))
        return discrete_solution(
            "vi", elasticity, trace, answer, residuals, status, reason, u_free=answer.u,
            pressure=trace.nodal_pressure(lam[nodes.facet_rows]),
            multiplier_breaks=trace.ordered_breaks(coordinate),
            active_constraints=count_active(qp, answer.u, reaction[kept]),
            details=NodalDetails(reactions=reaction, nodal_pressure=lam,
                                 contact_nodes=nodes.vertices),
            friction=None if friction is None else nodal_friction(
                friction, answer.u, reaction, tangential_of(answer), nodes, coordinate, frame))

    return Discretisation(formulation="vi", elasticity=elasticity, trace=trace, qp=qp,
                          recover=recover, row_coordinate=row_coordinate)

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
from scipy import sparse
from skfem import MeshTri

from formulations.base import ContactQP, DiscreteSolution, QPSolution, Residuals
from formulations.contact import (
    TraceNodes,
    contact_trace,
    gauss_legendre,
    lagrange_basis_1d,
    lagrange_nodes,
)
from formulations.discretisation import Discretisation, discrete_solution
from formulations.elasticity import assemble_elasticity, check_order
from formulations.evaluation import evaluate_on_trace
from formulations.kkt import count_active
from formulations.nodal_friction import (
    facet_interpolant,
    friction_rows,
    interleaved,
    nodal_friction,
    tangent_frame,
)
from formulations.registry import register_formulation
from formulations.surface_nodes import (
    nodal_pressures,
    surface_nodes,
    surface_pressure,
    surface_rows,
)
from scenes import Scene


@dataclass(frozen=True, eq=False)
class NodalDetails:
    """The nodal VI's own arrays: contact reactions (forces), lambda_h at the contact nodes
    (reactions through the lumped boundary mass) and the contact nodes."""

    reactions: np.ndarray
    nodal_pressure: np.ndarray
    contact_nodes: np.ndarray


def newton_cotes(order: int) -> np.ndarray:
    """int_0^1 L_k dt for the 1D Lagrange polynomials L_k on the equispaced nodes k / p (the
    lumped boundary mass per unit facet length: 1/2, 1/2 for P1; 1/6, 2/3, 1/6 for P2 --
    Simpson; 1/8, 3/8, 3/8, 1/8 for P3); all positive for p <= 3."""
    t, w = gauss_legendre(order + 1)
    return lagrange_basis_1d(order, t) @ w


def trace_nodes(mesh: MeshTri, trace, order: int) -> TraceNodes:
    """The constraint nodes of ``vi`` for P_order (module docstring)."""
    vertices, local = np.unique(trace.vertices, return_inverse=True)
    local = local.reshape(trace.vertices.shape)  # (2, n_facets): row of each facet end
    nv, nf, inner = vertices.size, trace.size, order - 1
    inside = nv + np.arange(nf * inner).reshape(nf, inner)
    facet_rows = np.column_stack([local[0], inside, local[1]])
    m = nv + nf * inner
    mass = newton_cotes(order)[None, :] * trace.length[:, None]  # (n_facets, p + 1)
    weight = np.bincount(facet_rows.ravel(), mass.ravel(), m)
    normal = np.array([np.bincount(facet_rows.ravel(), (mass * trace.normal[c][:, None]).ravel(),
                                   m) for c in (0, 1)])
    normal /= np.linalg.norm(normal, axis=0)
    t_inside = lagrange_nodes(order)[1:-1]
    points = np.concatenate([mesh.p[:, vertices], trace.points(t_inside).reshape(2, -1)], axis=1)
    return TraceNodes(points=points, normal=normal, weight=weight, facet_rows=facet_rows,
                      vertices=vertices)


def constraint_rows(elasticity, trace, nodes: TraceNodes,
                    directions: np.ndarray | None = None) -> sparse.csr_matrix:
    """B_i = n_i' u_h(x_i): the vertex DOFs directly, the nodes inside facets by evaluating the
    basis there (other basis functions vanish at a Lagrange node up to round-off, dropped).
    ``directions`` (2, m) replaces the normals n_i (the tangential rows of friction)."""
    nv = nodes.vertices.size
    directions = nodes.normal if directions is None else directions
    dofs = elasticity.basis.nodal_dofs[:, nodes.vertices]  # (2, nv)
    vertex_rows = sparse.csr_matrix((directions[:, :nv].ravel(),
                                     (np.tile(np.arange(nv), 2), dofs.ravel())),
                                    shape=(nv, elasticity.basis.N))
    inner = elasticity.order - 1
    if inner == 0:
        return vertex_rows
    t_inside = lagrange_nodes(elasticity.order)[1:-1]
    inside = evaluate_on_trace(elasticity.basis, trace, t_inside).matrix(directions[:, nv:])
    inside.data[np.abs(inside.data) < 1e-12] = 0.0
    inside.eliminate_zeros()
    return sparse.vstack([vertex_rows, inside], format="csr")


@register_formulation("vi", "primal variational inequality: nodal constraints "
                            "u_h(x_i).n_i <= g(x_i) at every Lagrange node of Gamma_C, "
                            "lambda_h from the nodal reactions; Tresca or Coulomb friction "
                            "on the same nodes (2D and 3D)", friction=(2, 3))
def discretise(scene: Scene, mesh: MeshTri, order: int = 1) -> Discretisation:
    elasticity = assemble_elasticity(scene, mesh, check_order(order))
    trace = contact_trace(scene, mesh)
    if trace.dim == 3:
        nodes = surface_nodes(mesh, trace, elasticity.order)
        rows = partial(surface_rows, elasticity, nodes)
    else:
        nodes = trace_nodes(mesh, trace, elasticity.order)
        rows = partial(constraint_rows, elasticity, trace, nodes)
    B = rows()  # along the normals; with a direction per node, along it
    m = nodes.weight.size
    G = np.asarray(scene.gap(nodes.points), dtype=float)
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

    def tangential_of(answer: QPSolution) -> np.ndarray:  # NaN where a solve failed
        if answer.tangential is not None:
            return answer.tangential
        return np.full(friction.T.shape[0], np.nan)

    def recover(answer: QPSolution, residuals: Residuals, status: str,
                reason: str) -> DiscreteSolution:
        reaction = np.maximum(answer.multipliers, 0.0)
        lam = (reaction / nodes.weight if trace.dim == 2
               else nodal_pressures(trace, nodes, reaction))
        values = lam[nodes.facet_rows]  # (n_facets, p + 1)

        def pressure(t):
            if trace.dim == 3:
                return surface_pressure(values, t)
            return facet_interpolant(values, t)

        return discrete_solution(
            "vi", elasticity, trace, answer, residuals, status, reason, u_free=answer.u,
            pressure=pressure,
            multiplier_breaks=np.sort(coordinate) if trace.dim == 2 else np.zeros(0),
            active_constraints=count_active(qp, answer.u, reaction),
            details=NodalDetails(reactions=reaction, nodal_pressure=lam,
                                 contact_nodes=nodes.vertices),
            friction=None if friction is None else nodal_friction(
                friction, answer.u, reaction, tangential_of(answer), nodes, coordinate, frame))

    return Discretisation(formulation="vi", elasticity=elasticity, trace=trace, qp=qp,
                          recover=recover, row_coordinate=coordinate)

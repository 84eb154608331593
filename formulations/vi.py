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

import numpy as np
from scipy import sparse
from skfem import MeshTri

from formulations.base import ContactQP, DiscreteSolution, QPSolution, Residuals
from formulations.contact import contact_trace
from formulations.discretisation import Discretisation, discrete_solution
from formulations.elasticity import assemble_elasticity
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
                            "u_h(x_i).n_i <= g(x_i), lambda_h from the nodal reactions")
def discretise(scene: Scene, mesh: MeshTri) -> Discretisation:
    elasticity = assemble_elasticity(scene, mesh)
    trace = contact_trace(scene, mesh)
    nodes, local = np.unique(trace.vertices, return_inverse=True)
    local = local.reshape(trace.vertices.shape)  # (2, n_facets): row of each facet end
    m = nodes.size
    weight = np.bincount(local.ravel(), np.tile(0.5 * trace.length, 2), m)  # int phi_i ds
    normal = np.array([np.bincount(local.ravel(), np.tile(0.5 * trace.length * trace.normal[c],
                                                           2), m) for c in (0, 1)])
    normal /= np.linalg.norm(normal, axis=0)

    dofs = elasticity.basis.nodal_dofs[:, nodes]  # (2, m)
    B = sparse.csr_matrix((normal.ravel(), (np.tile(np.arange(m), 2), dofs.ravel())),
                          shape=(m, elasticity.basis.N))
    points = mesh.p[:, nodes]
    G = np.asarray(scene.gap(points), dtype=float)
    # rows of B are dimensionless (a normal), so the multipliers are forces; row_scale 1
    qp = ContactQP(K=elasticity.K_free, F=elasticity.F[elasticity.free],
                   B=B[:, elasticity.free].tocsr(), G=G, row_scale=np.ones(m),
                   objective_scale=float(scene.material.young_modulus))
    coordinate = np.asarray(scene.contact_coordinate(points), dtype=float)

    def recover(answer: QPSolution, residuals: Residuals, status: str,
                reason: str) -> DiscreteSolution:
        reaction = np.maximum(answer.multipliers, 0.0)
        lam = reaction / weight
        a, b = lam[local[0]][:, None], lam[local[1]][:, None]
        return discrete_solution(
            "vi", elasticity, trace, answer, residuals, status, reason, u_free=answer.u,
            pressure=lambda t: a + (b - a) * np.asarray(t)[None, :],
            multiplier_breaks=np.sort(coordinate),
            active_constraints=count_active(qp, answer.u, reaction),
            details=NodalDetails(reactions=reaction, nodal_pressure=lam, contact_nodes=nodes))

    return Discretisation(formulation="vi", elasticity=elasticity, trace=trace, qp=qp,
                          recover=recover, row_coordinate=coordinate)

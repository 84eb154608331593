"""Quadrilaterals: Q1 and Q2 on 1-irregular hierarchies (``scenes.quad_hierarchy``), hanging
nodes joined by the constraints of ``formulations.cells.hanging_nodes`` (docs/theory.md, section
15).

A scene runs on quadrilaterals when its starting mesh is a tensor grid of triangles (every
built-in 2D scene): the grid's lines give the root cells, so no second scene definition is
needed.
"""

from __future__ import annotations

import numpy as np
from skfem import Basis, ElementQuad1, ElementQuad2

from formulations.cells.base import CellFamily, Plan, register_family
from formulations.cells.hanging_nodes import prolongation
from formulations.cells.quad_load import quad_body_load
from formulations.cells.tensor_stiffness import tensor_stiffness
from scenes.quad_hierarchy import QuadHierarchy, QuadLeafMesh, coarse_edges


def tensor_axes(scene) -> list[np.ndarray] | None:
    """The grid lines of a scene whose starting mesh is a tensor grid, else None."""
    p = scene.mesh.p
    axes = [np.unique(p[k]) for k in range(p.shape[0])]
    return axes if int(np.prod([a.size for a in axes])) == p.shape[1] else None


def not_a_grid(scene, dim: int, version: str) -> str | None:
    """Why ``scene`` has no ``version`` (quadrilateral, hexahedral) mesh made from its
    starting mesh, or None: it must be a tensor grid in ``dim`` dimensions."""
    axes = tensor_axes(scene)
    if axes is None or len(axes) != dim:
        return (f"scene {scene.name!r}: its starting mesh is not a tensor grid in {dim}D, so "
                f"it has no {version} version")
    return None


class Quadrilaterals(CellFamily):
    name, cell, dim, shape = "quad", "quad", 2, "quadrilaterals"
    tensor_product = True
    mesh_type = QuadLeafMesh
    elements = {1: ElementQuad1, 2: ElementQuad2}
    centroid_rule = (np.full((2, 1), 0.5), np.array([1.0]))  # the unit square

    def why_no_mesh(self, scene) -> str | None:
        return not_a_grid(scene, self.dim, "quadrilateral")

    def starting_mesh(self, scene) -> QuadLeafMesh:
        why = self.why_no_mesh(scene)
        if why is not None:
            raise ValueError(why)
        return QuadHierarchy.from_tensor(*tensor_axes(scene)).mesh()

    def refined(self, plan: Plan) -> QuadLeafMesh:
        return plan.mesh.hierarchy.refined(plan.marked).mesh()

    def count_free_dofs(self, scene, mesh, order: int) -> int:
        """Two per conforming Lagrange node off Gamma_D, counted from the leaf mesh: every
        vertex, and for Q2 every edge and cell, less the nodes a hanging node constrains (its
        vertex; for Q2 also the midpoints of its edge's halves). Gamma_D holds no hanging
        node (a boundary edge has one cell)."""
        hanging = mesh.hierarchy.hanging()[0].size
        dirichlet = scene.dirichlet_facets(mesh)
        clamped = np.unique(mesh.facets[:, dirichlet]).size
        nodes = mesh.p.shape[1] - hanging
        if order == 2:
            nodes += mesh.facets.shape[1] + mesh.t.shape[1] - 2 * hanging
            clamped += dirichlet.size
        return int(2 * (nodes - clamped))

    def stiffness(self, basis, lam: float, mu: float, order: int):
        """Vectorised over cells on the (p + 1)^2 Gauss points
        (formulations.cells.tensor_stiffness):
        exact on parallelograms."""
        return tensor_stiffness(basis, lam, mu, order)

    def stiffness_intorder(self, order: int) -> int:
        return 2 * order + 1  # the loads' rule: exact on parallelograms, one degree to spare

    def traction_intorder(self, order: int) -> int:
        return 2 * order + 2

    def body_load(self, body_force, basis, order: int) -> np.ndarray:
        """The cell rule, refined where f jumps (``formulations.cells.quad_load``)."""
        rule = Basis(basis.mesh, basis.elem, intorder=self.stiffness_intorder(order))
        return quad_body_load(body_force, rule)

    def constraint(self, basis):
        return prolongation(basis.mesh.hierarchy, basis)[0]

    def multiplier_groups(self, mesh, trace, h_over_H: float) -> np.ndarray:
        """The seed's T_CH: each contact edge's ancestor log2(H/h) levels up in the hierarchy
        (one level for h/H = 1/2), numbered along Gamma_C (docs/theory.md, section 15.3). An
        ancestor that holds a finer group (a leaf too coarse to go the whole way up, next to
        refined ones) takes that group in: segments are runs along Gamma_C, never nested."""
        levels_up = max(0, int(round(-np.log2(h_over_H))))
        groups = coarse_edges(mesh.hierarchy, trace.element, trace.normal, levels_up)
        _, inverse = np.unique(groups, return_inverse=True)
        s0, s1 = trace.coordinate
        low = np.full(inverse.max(initial=-1) + 1, np.inf)
        high = np.full(low.size, -np.inf)
        np.minimum.at(low, inverse, s0)
        np.maximum.at(high, inverse, s1)
        # a new segment where a facet's group starts past everything before it reaches
        reach = np.maximum.accumulate(high[inverse])
        tol = 1e-12 * (np.abs(trace.coordinate).max(initial=0.0) + 1.0)
        new = np.r_[True, low[inverse][1:] >= reach[:-1] - tol]
        return np.cumsum(new) - 1

    def conforming(self, values: np.ndarray, basis) -> np.ndarray:
        P, kept = prolongation(basis.mesh.hierarchy, basis)
        return (P @ np.atleast_2d(values)[:, kept].T).T.reshape(np.shape(values))


QUADRILATERALS = register_family(Quadrilaterals(), "quadrilaterals: Q1-Q2 on hierarchical "
                                                   "meshes with hanging nodes")

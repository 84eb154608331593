"""Quadrilaterals: Q1 and Q2 on 1-irregular hierarchies (``scenes.quad_hierarchy``), hanging
nodes joined by the constraints of ``formulations.hanging_nodes`` (docs/theory.md, section 15).

A scene runs on quadrilaterals when its starting mesh is a tensor grid of triangles (every
built-in 2D scene): the grid's lines give the root cells, so no second scene definition is
needed.
"""

from __future__ import annotations

import numpy as np
from skfem import Basis, ElementQuad1, ElementQuad2

from formulations.cells.base import CellFamily, Plan, register_family
from formulations.hanging_nodes import prolongation
from formulations.quad_load import quad_body_load
from scenes.quad_hierarchy import QuadHierarchy, QuadLeafMesh


def tensor_axes(scene) -> list[np.ndarray] | None:
    """The grid lines of a scene whose starting mesh is a tensor grid, else None."""
    p = scene.mesh.p
    axes = [np.unique(p[k]) for k in range(p.shape[0])]
    return axes if int(np.prod([a.size for a in axes])) == p.shape[1] else None


def not_a_grid(scene, shape: str) -> str | None:
    """Why ``scene`` has no mesh of ``shape`` made from its starting mesh, or None."""
    if tensor_axes(scene) is None:
        return (f"scene {scene.name!r}: its starting mesh is not a tensor grid, so it has no "
                f"mesh of {shape}")
    return None


class Quadrilaterals(CellFamily):
    name, cell, dim, shape = "quad", "quad", 2, "quadrilaterals"
    tensor_product = True
    mesh_type = QuadLeafMesh
    elements = {1: ElementQuad1, 2: ElementQuad2}
    centroid_rule = (np.full((2, 1), 0.5), np.array([1.0]))  # the unit square

    def why_no_mesh(self, scene) -> str | None:
        return not_a_grid(scene, self.shape)

    def starting_mesh(self, scene) -> QuadLeafMesh:
        why = self.why_no_mesh(scene)
        if why is not None:
            raise ValueError(why)
        return QuadHierarchy.from_tensor(*tensor_axes(scene)).mesh()

    def refined(self, plan: Plan) -> QuadLeafMesh:
        return plan.mesh.hierarchy.refined(plan.marked).mesh()

    def count_free_dofs(self, scene, mesh, order: int) -> int:
        """Two per conforming Lagrange node off Gamma_D (a hanging node and the DOFs inside
        the halves of its edge are not unknowns)."""
        basis = Basis(mesh, self.vector_element(order), intorder=1)
        P = self.constraint(basis)
        fixed = np.zeros(basis.N)
        fixed[basis.get_dofs(scene.dirichlet_facets(mesh)).all()] = 1.0
        return int(np.count_nonzero(np.asarray(P.T @ fixed).ravel() == 0))

    def vector_element(self, order: int):
        from skfem import ElementVector
        return ElementVector(self.elements[order]())

    def stiffness_intorder(self, order: int) -> int:
        return 2 * order + 1  # exact on parallelograms, with one degree to spare

    def traction_intorder(self, order: int) -> int:
        return 2 * order + 2

    def body_load(self, body_force, basis, order: int) -> np.ndarray:
        """The cell rule, refined where f jumps (``formulations.quad_load``)."""
        rule = Basis(basis.mesh, basis.elem, intorder=self.stiffness_intorder(order))
        return quad_body_load(body_force, rule)

    def constraint(self, basis):
        return prolongation(basis.mesh.hierarchy, basis)[0]


QUADRILATERALS = register_family(Quadrilaterals(), "quadrilaterals: Q1-Q2 on hierarchical "
                                                   "meshes with hanging nodes")

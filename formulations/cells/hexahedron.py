"""Hexahedra: Q1 and Q2 on 1-irregular hierarchies of a scene's grid of cubes
(``scenes.hex_hierarchy``), refined uniformly or where marked; the nodes that finer neighbours
put on a leaf's edges and faces take the leaf's field there
(``formulations.cells.hex_constraints``; docs/theory.md, sections 15.4-15.6). Their contact
boundary is the quadrilateral faces on Gamma_C (``formulations.contact.quadrilaterals``)."""

from __future__ import annotations

import numpy as np
from skfem import Basis, ElementHex1, ElementHex2
from skfem.assembly import Dofs

from formulations.cells.base import CellFamily, Plan, register_family
from formulations.cells.hanging_nodes import substituted
from formulations.cells.hex_constraints import constraint_rows
from formulations.cells.quad_load import quad_body_load
from formulations.cells.quadrilateral import not_a_grid, tensor_axes
from formulations.cells.tensor_stiffness import tensor_stiffness
from scenes.hex_hierarchy import HexHierarchy, HexLeafMesh


class Hexahedra(CellFamily):
    name, cell, dim, shape = "hex", "quad", 3, "hexahedra"
    tensor_product = True
    mesh_type = HexLeafMesh
    elements = {1: ElementHex1, 2: ElementHex2}
    centroid_rule = (np.full((3, 1), 0.5), np.array([1.0]))  # the unit cube
    contact_boundary = "quadrilaterals"

    def why_no_mesh(self, scene) -> str | None:
        return not_a_grid(scene, self.dim, "hexahedral")

    def starting_mesh(self, scene) -> HexLeafMesh:
        why = self.why_no_mesh(scene)
        if why is not None:
            raise ValueError(why)
        return HexHierarchy.from_tensor(*tensor_axes(scene)).mesh()

    def refined(self, plan: Plan) -> HexLeafMesh:
        return plan.mesh.hierarchy.refined(plan.marked).mesh()

    def count_free_dofs(self, scene, mesh, order: int) -> int:
        """Three per Lagrange node that neither hangs nor lies on a clamped face (counted on
        scikit-fem's scalar numbering, before anything is assembled)."""
        dofs, (rows, _, _) = scalar_constraints(mesh, order)
        fixed = np.zeros(dofs.N, dtype=bool)
        fixed[dofs.get_facet_dofs(scene.dirichlet_facets(mesh)).all()] = True
        fixed[rows] = True
        return int(3 * np.count_nonzero(~fixed))

    def stiffness(self, basis, lam: float, mu: float, order: int):
        """Vectorised over cells on the (p + 1)^3 Gauss points
        (formulations.cells.tensor_stiffness): exact on parallelepipeds."""
        return tensor_stiffness(basis, lam, mu, order)

    def stiffness_intorder(self, order: int) -> int:
        return 2 * order  # (p + 1)^3 Gauss points: exact on parallelepipeds

    def body_load(self, body_force, basis, order: int) -> np.ndarray:
        """The cell rule, refined where f jumps (``formulations.cells.quad_load``)."""
        rule = Basis(basis.mesh, basis.elem, intorder=2 * order + 1)
        return quad_body_load(body_force, rule)

    def constraint(self, basis):
        return prolongation(basis)[0]

    def conforming(self, values: np.ndarray, basis) -> np.ndarray:
        P, kept = prolongation(basis)
        return (P @ np.atleast_2d(values)[:, kept].T).T.reshape(np.shape(values))


def scalar_constraints(mesh, order: int):
    """The scalar Q_order numbering of the leaf mesh and its hanging-node triplets
    (``formulations.cells.hex_constraints``)."""
    element = Hexahedra.elements[order]()
    dofs = Dofs(mesh, element)
    return dofs, constraint_rows(mesh, dofs, element, order)


def prolongation(basis):
    """P and the conforming DOFs of a scalar or vector Q1 or Q2 basis on a leaf mesh: each
    component constrained alike (scikit-fem numbers component c of scalar DOF s as d s + c)."""
    scalar = getattr(basis.elem, "elem", basis.elem)  # a vector element's component
    order = next(p for p, kind in Hexahedra.elements.items() if type(scalar) is kind)
    dofs, (rows, cols, weights) = scalar_constraints(basis.mesh, order)
    d = basis.N // dofs.N
    components = np.arange(d)[:, None]
    return substituted((d * rows + components).ravel(), (d * cols + components).ravel(),
                       np.tile(weights, d), basis.N)


HEXAHEDRA = register_family(Hexahedra(), "hexahedra: Q1-Q2 on hierarchical meshes with "
                                         "hanging nodes")

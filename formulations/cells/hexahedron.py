"""Hexahedra: Q1 on tensor grids, refined uniformly (docs/theory.md, sections 15.4-15.6). Their
contact boundary is the quadrilateral faces on Gamma_C (``formulations.contact.quadrilaterals``).
Adaptive refinement would need hanging nodes on faces and edges: not built, so an adaptive run
on hexahedra is a skipped row that says so."""

from __future__ import annotations

import numpy as np
from skfem import Basis, ElementHex1, MeshHex
from skfem.mesh import MeshHex1

from formulations.cells.base import CellFamily, register_family
from formulations.cells.quad_load import quad_body_load
from formulations.cells.quadrilateral import not_a_grid, tensor_axes


class Hexahedra(CellFamily):
    name, cell, dim, shape = "hex", "quad", 3, "hexahedra"
    tensor_product = True
    mesh_type = MeshHex1
    elements = {1: ElementHex1}
    centroid_rule = (np.full((3, 1), 0.5), np.array([1.0]))  # the unit cube
    adaptive = False
    contact_boundary = "quadrilaterals"

    def why_no_mesh(self, scene) -> str | None:
        return not_a_grid(scene, self.dim, "hexahedral")

    def starting_mesh(self, scene) -> MeshHex:
        why = self.why_no_mesh(scene)
        if why is not None:
            raise ValueError(why)
        return MeshHex.init_tensor(*tensor_axes(scene))

    def count_free_dofs(self, scene, mesh, order: int) -> int:
        """Three per vertex off the clamped faces."""
        clamped = np.unique(mesh.facets[:, scene.dirichlet_facets(mesh)]).size
        return int(3 * (mesh.p.shape[1] - clamped))

    def stiffness_intorder(self, order: int) -> int:
        return 2 * order  # (p + 1)^3 Gauss points: exact on parallelepipeds

    def body_load(self, body_force, basis, order: int) -> np.ndarray:
        """The cell rule, refined where f jumps (``formulations.cells.quad_load``)."""
        rule = Basis(basis.mesh, basis.elem, intorder=2 * order + 1)
        return quad_body_load(body_force, rule)


HEXAHEDRA = register_family(Hexahedra(), "hexahedra: Q1 on tensor grids, uniform refinement")

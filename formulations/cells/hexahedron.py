"""Hexahedra: Q1 on 1-irregular hierarchies of a scene's grid of cubes
(``scenes.hex_hierarchy``), refined uniformly or where marked; hanging nodes at the midpoints
of split edges and the centres of split faces take the coarse cell's trilinear trace there
(docs/theory.md, sections 15.4-15.6). Their contact boundary is the quadrilateral faces on
Gamma_C (``formulations.contact.quadrilaterals``)."""

from __future__ import annotations

import numpy as np
from skfem import Basis, ElementHex1

from formulations.cells.base import CellFamily, Plan, register_family
from formulations.cells.hanging_nodes import substituted
from formulations.cells.quad_load import quad_body_load
from formulations.cells.quadrilateral import not_a_grid, tensor_axes
from scenes.hex_hierarchy import HexHierarchy, HexLeafMesh


class Hexahedra(CellFamily):
    name, cell, dim, shape = "hex", "quad", 3, "hexahedra"
    tensor_product = True
    mesh_type = HexLeafMesh
    elements = {1: ElementHex1}
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
        """Three per vertex that neither hangs nor lies on a clamped face."""
        fixed = np.zeros(mesh.p.shape[1], dtype=bool)
        fixed[mesh.facets[:, scene.dirichlet_facets(mesh)]] = True
        fixed[hanging_vertices(mesh)[0]] = True
        return int(3 * np.count_nonzero(~fixed))

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


def hanging_vertices(mesh: HexLeafMesh) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The Q1 constraints of the leaf mesh's vertices as (hanging vertex, vertex, weight)
    triplets: a split edge's midpoint is the mean of its ends, a split face's centre the mean
    of its four corners (the trilinear trace there)."""
    hierarchy = mesh.hierarchy
    used, _ = hierarchy.leaf_vertices()
    node, a, b = (np.searchsorted(used, v) for v in hierarchy.hanging_edges())
    centre, corners = (np.searchsorted(used, v) for v in hierarchy.hanging_faces())
    rows = np.concatenate([node, node, np.tile(centre, 4)])
    cols = np.concatenate([a, b, corners.ravel()])
    weights = np.concatenate([np.full(2 * node.size, 0.5), np.full(corners.size, 0.25)])
    return rows, cols, weights


def prolongation(basis):
    """P and the conforming DOFs of a vector Q1 basis on a leaf mesh (each component
    constrained alike)."""
    rows, cols, weights = hanging_vertices(basis.mesh)
    nodal = basis.nodal_dofs  # (components, vertices)
    return substituted(nodal[:, rows].ravel(), nodal[:, cols].ravel(),
                       np.tile(weights, nodal.shape[0]), basis.N)


HEXAHEDRA = register_family(Hexahedra(), "hexahedra: Q1 on hierarchical meshes with hanging "
                                         "nodes")

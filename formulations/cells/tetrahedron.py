"""Tetrahedra: Lagrange P1 and P2 (scikit-fem has no P3 tetrahedron), scikit-fem's
refinement, local stiffness matrices on affine tetrahedra (docs/theory.md, section 14)."""

from __future__ import annotations

import numpy as np
from skfem import ElementTetP1, ElementTetP2
from skfem.mesh import MeshTet1

from formulations.cells.base import CellFamily, register_family
from formulations.cells.tet_stiffness import tet_stiffness
from formulations.cells.triangle import Triangles


class Tetrahedra(Triangles):
    name, cell, dim, shape = "tet", "tri", 3, "tetrahedra"
    # friction in 3D bounds a disc per point (a second-order cone); the registered formulations
    # and estimators say for themselves whether they model it (register_formulation(...,
    # friction=(2, 3)))
    friction = True
    contact_boundary = "triangles"
    mesh_type = MeshTet1
    elements = {1: ElementTetP1, 2: ElementTetP2}
    centroid_rule = (np.full((3, 1), 1.0 / 4.0), np.array([1.0 / 6.0]))  # weight = the volume

    def count_free_dofs(self, scene, mesh, order: int) -> int:
        """Three per Lagrange node (one per vertex, p - 1 per edge) off the clamped facets."""
        dirichlet = scene.dirichlet_facets(mesh)
        clamped = (np.unique(mesh.facets[:, dirichlet]).size
                   + (order - 1) * np.unique(mesh.f2e[:, dirichlet]).size)
        return int(3 * (mesh.p.shape[1] + (order - 1) * mesh.edges.shape[1] - clamped))

    def predict_free_dofs(self, scene, plan, order: int) -> int:
        return CellFamily.predict_free_dofs(self, scene, plan, order)

    def stiffness(self, basis, lam: float, mu: float, order: int):
        return tet_stiffness(basis, lam, mu)


TETRAHEDRA = register_family(Tetrahedra(), "tetrahedra: Lagrange P1-P2, scikit-fem's "
                                           "refinement")

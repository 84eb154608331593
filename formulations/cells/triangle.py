"""Triangles: Lagrange P1-P3, red-green-blue refinement (``scenes.topology``), the closed-form
P1 and P2 stiffness matrices (docs/theory.md, sections 7 and 9)."""

from __future__ import annotations

import numpy as np
from skfem import Basis, ElementTriP1, ElementTriP2, ElementTriP3
from skfem.mesh import MeshTri1

from formulations.cells.base import CellFamily, Plan, register_family
from formulations.cells.load import body_load
from formulations.cells.p1_stiffness import p1_stiffness
from formulations.cells.p2_stiffness import p2_stiffness
from scenes.topology import refinement_plan


def lagrange_dofs(vertices: int, edges: int, triangles: int, order: int) -> int:
    """Scalar P_order DOFs of a mesh: one per vertex, p - 1 per edge, (p-1)(p-2)/2 inside."""
    return vertices + (order - 1) * edges + (order - 1) * (order - 2) // 2 * triangles


class Triangles(CellFamily):
    name, cell, dim, shape = "tri", "tri", 2, "triangles"
    mesh_type = MeshTri1
    elements = {1: ElementTriP1, 2: ElementTriP2, 3: ElementTriP3}
    centroid_rule = (np.full((2, 1), 1.0 / 3.0), np.array([0.5]))  # weight = the area
    friction = True  # the registered formulations say for themselves

    def refinement(self, mesh, marked=None) -> Plan:
        return Plan(self, mesh, marked, refinement_plan(mesh, marked))

    def refined(self, plan: Plan):
        return plan.detail.refined

    def count_free_dofs(self, scene, mesh, order: int) -> int:
        """Two per Lagrange node, none on a node of a clamped facet."""
        dirichlet = scene.dirichlet_facets(mesh)
        clamped = np.unique(mesh.facets[:, dirichlet]).size + (order - 1) * dirichlet.size
        nodes = lagrange_dofs(mesh.p.shape[1], mesh.facets.shape[1], mesh.t.shape[1], order)
        return int(2 * (nodes - clamped))

    def predict_free_dofs(self, scene, plan: Plan, order: int) -> int:
        """``count_free_dofs`` of the refined mesh without splitting a triangle: a
        red-green-blue split adds one vertex per split facet, which becomes two facets (two
        clamped ones on Gamma_D), and k triangles and k interior edges to a triangle with k
        split edges. A plan that scikit-fem carries out itself is counted after refining."""
        detail, mesh = plan.detail, plan.mesh
        if detail.split is None:
            return (predict_uniform_free_dofs(scene, mesh, order) if detail.marked is None
                    else self.count_free_dofs(scene, detail.refined, order))
        dirichlet = scene.dirichlet_facets(mesh)
        new_vertices = detail.new_vertices()
        more = int(detail.new_elements_per_element().sum())
        split_clamped = int(np.count_nonzero(detail.split[dirichlet]))
        clamped = (np.unique(mesh.facets[:, dirichlet]).size + split_clamped
                   + (order - 1) * (dirichlet.size + split_clamped))
        nodes = lagrange_dofs(mesh.p.shape[1] + new_vertices,
                              mesh.facets.shape[1] + new_vertices + more,
                              mesh.t.shape[1] + more, order)
        return int(2 * (nodes - clamped))

    def stiffness(self, basis, lam: float, mu: float, order: int):
        if order == 1:  # constant strains: closed-form local matrices
            return p1_stiffness(basis.mesh, lam, mu)
        if order == 2:  # the same straight into CSR
            return p2_stiffness(basis.mesh, lam, mu)
        return super().stiffness(basis, lam, mu, order)

    def body_load(self, body_force, basis, order: int) -> np.ndarray:
        """scikit-fem's default rule, of order 2p, refined where f jumps
        (``formulations.cells.load``)."""
        return body_load(body_force, Basis(basis.mesh, basis.elem))


def predict_uniform_free_dofs(scene, mesh, order: int = 1) -> int:
    """``count_free_dofs`` of ``mesh.refined()``, without refining: uniform refinement adds one
    vertex per edge, splits every edge in two and adds three inside every triangle (which
    becomes four); each clamped facet adds one clamped vertex and becomes two facets."""
    dirichlet = scene.dirichlet_facets(mesh)
    nv, ne, nt = mesh.p.shape[1], mesh.facets.shape[1], mesh.t.shape[1]
    clamped = (np.unique(mesh.facets[:, dirichlet]).size + dirichlet.size
               + (order - 1) * 2 * dirichlet.size)
    return int(2 * (lagrange_dofs(nv + ne, 2 * ne + 3 * nt, 4 * nt, order) - clamped))


TRIANGLES = register_family(Triangles(), "triangles: Lagrange P1-P3, red-green-blue "
                                         "refinement")

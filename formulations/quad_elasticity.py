"""Q1 and Q2 linear elasticity on a 1-irregular quadrilateral hierarchy: the Galerkin system
P' K P, P' F in the conforming space of ``formulations.hanging_nodes`` (docs/theory.md,
section 15).

K and F are assembled by scikit-fem on the leaf cells as if they were unconnected across the
edges with a hanging node; P joins them. The boundary of the body is the leaf mesh's boundary
minus those edges (each side of such an edge is a boundary facet to scikit-fem).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import sparse
from skfem import Basis, ElementQuad1, ElementQuad2, ElementVector, FacetBasis, LinearForm, asm
from skfem.helpers import dot
from skfem.models.elasticity import linear_elasticity

from formulations.hanging_nodes import prolongation
from formulations.quad_load import quad_body_load
from scenes import Scene
from scenes.quad_hierarchy import QuadHierarchy, edge_keys

QUAD_ELEMENTS = {1: ElementQuad1, 2: ElementQuad2}


@dataclass(frozen=True, eq=False)
class QuadElasticity:
    """The conforming system on a hierarchy's leaves: ``K`` and ``F`` over the conforming DOFs
    (``P`` maps them to the cell DOFs of ``basis``), ``free`` the conforming DOFs off the
    clamped boundary (positions in the conforming numbering)."""

    hierarchy: QuadHierarchy
    basis: Basis
    lame: tuple[float, float]
    P: sparse.csr_matrix
    K: sparse.csr_matrix
    F: np.ndarray
    free: np.ndarray
    boundary: np.ndarray  # the facets of the leaf mesh on the body's boundary
    clamped: np.ndarray  # those on Gamma_D
    order: int = 1

    @property
    def ndofs(self) -> int:
        return int(self.free.size)

    def expand(self, u_free: np.ndarray) -> np.ndarray:
        """The cell-DOF vector P u of the free values (the clamped ones 0)."""
        u = np.zeros(self.P.shape[1])
        u[self.free] = u_free
        return self.P @ u


def body_boundary(hierarchy: QuadHierarchy, mesh) -> np.ndarray:
    """The leaf mesh's boundary facets that lie on the body's boundary: not an edge with a
    hanging node, nor a half of one."""
    used, _ = hierarchy.leaf_vertices()
    node, a, b = hierarchy.hanging()
    inner = np.concatenate([edge_keys(a, b), edge_keys(a, node), edge_keys(node, b)])
    facets = mesh.boundary_facets()
    keys = edge_keys(used[mesh.facets[0, facets]], used[mesh.facets[1, facets]])
    return facets[~np.isin(keys, inner)]


def boundary_facets_of(predicate, mesh, boundary: np.ndarray) -> np.ndarray:
    """The facets of ``boundary`` whose midpoint satisfies ``predicate``."""
    mid = mesh.p[:, mesh.facets[:, boundary]].mean(axis=1)
    return boundary[np.asarray(predicate(mid), dtype=bool)]


def count_quad_dofs(scene: Scene, hierarchy: QuadHierarchy, order: int = 1) -> int:
    """The unknowns ``assemble_quad_elasticity`` would give, without assembling K: two per
    conforming Lagrange node off Gamma_D (a hanging node and the DOFs inside the halves of
    its edge are not unknowns)."""
    mesh = hierarchy.mesh()
    basis = Basis(mesh, ElementVector(QUAD_ELEMENTS[order]()), intorder=1)
    _, kept = prolongation(hierarchy, basis)
    clamped = boundary_facets_of(scene.is_dirichlet, mesh, body_boundary(hierarchy, mesh))
    return int(kept.size - np.unique(basis.get_dofs(clamped).all()).size)


def assemble_quad_elasticity(scene: Scene, hierarchy: QuadHierarchy,
                             order: int = 1) -> QuadElasticity:
    """P' K P and P' F for Q_order displacements on the leaves of ``hierarchy``, with the
    scene's material, loads and clamped boundary."""
    if order not in QUAD_ELEMENTS:
        raise ValueError(f"order={order!r} is not one of {', '.join(map(str, QUAD_ELEMENTS))} "
                         "on quadrilaterals")
    mesh = hierarchy.mesh()
    basis = Basis(mesh, ElementVector(QUAD_ELEMENTS[order]()), intorder=2 * order + 1)
    lam, mu = scene.material.lame
    P, _ = prolongation(hierarchy, basis)
    K_cells = asm(linear_elasticity(lam, mu), basis)
    F_cells = np.zeros(basis.N)
    if scene.body_force is not None:  # the basis's rule, refined where f jumps
        F_cells += quad_body_load(scene.body_force, basis)
    boundary = body_boundary(hierarchy, mesh)
    clamped = boundary_facets_of(scene.is_dirichlet, mesh, boundary)
    loaded = np.setdiff1d(boundary, np.union1d(
        clamped, boundary_facets_of(scene.is_contact, mesh, boundary)))
    if scene.traction is not None and loaded.size:
        @LinearForm
        def surface(v, w):
            return dot(scene.traction(w.x), v)

        F_cells += asm(surface, FacetBasis(mesh, basis.elem, facets=loaded,
                                           intorder=2 * order + 2))
    fixed = np.zeros(basis.N, dtype=bool)
    fixed[basis.get_dofs(clamped).all()] = True
    conforming_fixed = np.asarray(P.T @ fixed.astype(float)).ravel() > 0
    return QuadElasticity(hierarchy=hierarchy, basis=basis, lame=(lam, mu), P=P,
                          K=(P.T @ K_cells @ P).tocsr(), F=P.T @ F_cells,
                          free=np.flatnonzero(~conforming_fixed), boundary=boundary,
                          clamped=clamped, order=order)

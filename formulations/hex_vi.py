"""The VI on hexahedra: trilinear Q1 displacements on a scene's tensor grid of cubes (uniform
refinement, so no hanging node), nodal constraints u_h(x_i) . n_i <= g(x_i) at every vertex of
Gamma_C (docs/theory.md, sections 3 and 15).

Gamma_C's faces are quadrilaterals; a vertex's normal is the area-weighted mean of its faces'
outer normals, its lumped boundary mass a quarter of each face's area.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import sparse
from skfem import Basis, ElementHex1, ElementVector, FacetBasis, LinearForm, MeshHex, asm
from skfem.helpers import dot
from skfem.models.elasticity import linear_elasticity

from formulations.base import ContactQP
from formulations.cells import family_for
from formulations.elasticity import Elasticity, free_dofs
from formulations.solvers.registry import FAST_SOLVER, SOLVERS
from scenes import Scene


def hex_mesh(scene: Scene, refinements: int = 0) -> MeshHex:
    """The cubes of a 3D scene's tensor grid (the hexahedral family's starting mesh), refined
    uniformly; ValueError for a scene whose starting mesh is not a 3D tensor grid."""
    return family_for("quad", 3).starting_mesh(scene).refined(refinements)


def assemble_hex_elasticity(scene: Scene, mesh: MeshHex) -> Elasticity:
    """K, F and the free DOFs of Q1 on ``mesh`` (conforming: K over all DOFs)."""
    element = ElementVector(ElementHex1())
    # 2 x 2 x 2 Gauss points: exact for products of trilinear gradients on parallelepipeds
    basis = Basis(mesh, element, intorder=2)
    lam, mu = scene.material.lame
    F = np.zeros(basis.N)
    if scene.body_force is not None:
        @LinearForm
        def body(v, w):
            return dot(scene.body_force(w.x), v)

        F += asm(body, Basis(mesh, element, intorder=4))
    neumann = scene.neumann_facets(mesh)
    if scene.traction is not None and neumann.size:
        @LinearForm
        def surface(v, w):
            return dot(scene.traction(w.x), v)

        F += asm(surface, FacetBasis(mesh, element, facets=neumann, intorder=4))
    return Elasticity(mesh=mesh, basis=basis, lame=(lam, mu),
                      K=asm(linear_elasticity(lam, mu), basis).tocsr(), F=F,
                      free=free_dofs(basis, scene.dirichlet_facets(mesh)), order=1)


def face_normals(mesh: MeshHex, faces: np.ndarray) -> np.ndarray:
    """Outer normals (3, n) of quadrilateral faces, of length their area (half the cross
    product of the diagonals; exact for planar faces)."""
    corners = mesh.p[:, mesh.facets[:, faces]]  # (3, 4, n); skfem orders a face's corners
    # around it, so 0-2 and 1-3 are its diagonals
    normal = 0.5 * np.cross(corners[:, 2] - corners[:, 0], corners[:, 3] - corners[:, 1],
                            axis=0)
    centre = corners.mean(axis=1)
    inside = mesh.p[:, mesh.t[:, mesh.f2t[0, faces]]].mean(axis=1)
    return normal * np.where((normal * (centre - inside)).sum(axis=0) < 0, -1.0, 1.0)


@dataclass(frozen=True, eq=False)
class HexContactSolution:
    """A solved level: ``u`` over all DOFs (0 on Gamma_D), the nodal reactions, the status."""

    elasticity: Elasticity
    u: np.ndarray
    reactions: np.ndarray
    status: str
    reason: str

    @property
    def energy(self) -> float:
        return self.elasticity.energy(self.u)

    @property
    def contact_force(self) -> float:
        return float(self.reactions.sum())


def solve_hex_vi(scene: Scene, mesh: MeshHex, solver: str = FAST_SOLVER,
                 **options) -> HexContactSolution:
    """The Q1 VI on ``mesh`` with a registered QP solver."""
    elasticity = assemble_hex_elasticity(scene, mesh)
    faces = scene.contact_facets(mesh)
    normal = face_normals(mesh, faces)
    vertices, rows = np.unique(mesh.facets[:, faces], return_inverse=True)
    rows = rows.reshape(4, -1)
    vertex_normal = np.array([np.bincount(rows.ravel(), np.tile(c, 4), vertices.size)
                              for c in normal])
    vertex_normal /= np.linalg.norm(vertex_normal, axis=0)
    dofs = elasticity.basis.nodal_dofs[:, vertices]  # (3, m)
    m = vertices.size
    B = sparse.csr_matrix((vertex_normal.ravel(), (np.tile(np.arange(m), 3), dofs.ravel())),
                          shape=(m, elasticity.basis.N))
    free = elasticity.free
    qp = ContactQP(K=elasticity.K_free, F=elasticity.F[free], B=B[:, free].tocsr(),
                   G=np.asarray(scene.gap(mesh.p[:, vertices]), dtype=float),
                   row_scale=np.ones(m), objective_scale=float(scene.material.young_modulus),
                   near_null=elasticity.rigid_modes)
    answer = SOLVERS.get(solver)(qp, **options)
    if answer.u is None or answer.multipliers is None or not np.all(np.isfinite(answer.u)):
        return HexContactSolution(elasticity, np.full(elasticity.basis.N, np.nan),
                                  np.full(m, np.nan), "failed",
                                  f"{answer.status}: {answer.reason or 'no solution'}")
    return HexContactSolution(elasticity, elasticity.expand(answer.u),
                              np.maximum(answer.multipliers, 0.0), answer.status, answer.reason)

"""P1 (triangles) linear elasticity on scikit-fem: stiffness, loads, stresses
(docs/theory.md, section 1).

Plane stress uses lambda* = E nu / (1 - nu^2), plane strain lambda = E nu / ((1+nu)(1-2nu)).
Everything is vectorised over elements by scikit-fem's assembly.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import sparse
from skfem import Basis, ElementTriP1, ElementVector, FacetBasis, LinearForm, MeshTri, asm
from skfem.helpers import dot
from skfem.models.elasticity import linear_elasticity

from scenes import Scene


@dataclass(frozen=True, eq=False)
class Elasticity:
    """Assembled elasticity operator on one mesh; K and F are over ALL DOFs, ``free`` excludes
    the clamped DOFs on Gamma_D (u = 0 there)."""

    mesh: MeshTri
    basis: Basis
    lame: tuple[float, float]
    K: sparse.csr_matrix
    F: np.ndarray
    free: np.ndarray

    @property
    def ndofs(self) -> int:
        """Number of unknowns (free DOFs)."""
        return int(self.free.size)

    @property
    def K_free(self) -> sparse.csr_matrix:
        return self.K[self.free][:, self.free].tocsr()

    def expand(self, u_free: np.ndarray) -> np.ndarray:
        """Full DOF vector from the free DOFs (zero on Gamma_D)."""
        u = np.zeros(self.basis.N)
        u[self.free] = u_free
        return u

    def energy(self, u: np.ndarray) -> float:
        """E(u) = 1/2 u'Ku - F'u (the energy functional of docs/theory.md, section 1)."""
        return float(0.5 * u @ (self.K @ u) - self.F @ u)

    def nodal(self, u: np.ndarray) -> np.ndarray:
        """Nodal displacement field, shape (2, n_vertices)."""
        return u[self.basis.nodal_dofs]

    def element_stress(self, u: np.ndarray) -> np.ndarray:
        """Constant stress (s11, s22, s12) per element for the P1 field u; shape (3, n_elements)."""
        grad = self.basis.interpolate(u).grad[:, :, :, 0]  # P1: constant per element
        return stress_from_gradient(grad, *self.lame)


def element_diameters(mesh: MeshTri) -> np.ndarray:
    """Longest edge of every triangle (h_T)."""
    p = mesh.p[:, mesh.t]
    return np.max([np.linalg.norm(p[:, i] - p[:, (i + 1) % 3], axis=0) for i in range(3)], axis=0)


def stress_from_gradient(grad: np.ndarray, lam: float, mu: float) -> np.ndarray:
    """sigma = lam tr(eps) I + 2 mu eps from grad[i, j] = d u_i / d x_j; returns (s11, s22, s12)."""
    e11, e22 = grad[0, 0], grad[1, 1]
    e12 = 0.5 * (grad[0, 1] + grad[1, 0])
    tr = e11 + e22
    return np.array([lam * tr + 2 * mu * e11, lam * tr + 2 * mu * e22, 2 * mu * e12])


def von_mises(stress: np.ndarray) -> np.ndarray:
    """Plane-stress von Mises stress sqrt(s11^2 + s22^2 - s11 s22 + 3 s12^2) (docs/theory.md,
    section 1)."""
    s11, s22, s12 = stress
    return np.sqrt(s11**2 + s22**2 - s11 * s22 + 3 * s12**2)


def assemble_elasticity(scene: Scene, mesh: MeshTri) -> Elasticity:
    """Stiffness K, load F = (f, v) + (q, v)_{Gamma_N}, and the free DOFs for ``mesh``."""
    basis = Basis(mesh, ElementVector(ElementTriP1()))
    lam, mu = scene.material.lame
    # P1 strains are constant per element: the centroid rule is exact and 3x cheaper
    centroid = Basis(mesh, basis.elem, quadrature=(np.full((2, 1), 1.0 / 3.0), np.array([0.5])))
    K = asm(linear_elasticity(lam, mu), centroid).tocsr()
    F = np.zeros(basis.N)
    if scene.body_force is not None:
        @LinearForm
        def body(v, w):
            return dot(scene.body_force(w.x), v)

        F += asm(body, basis)
    neumann = scene.neumann_facets(mesh)
    if scene.traction is not None and neumann.size:
        @LinearForm
        def surface(v, w):
            return dot(scene.traction(w.x), v)

        F += asm(surface, FacetBasis(mesh, basis.elem, facets=neumann, intorder=4))
    clamped = basis.get_dofs(scene.dirichlet_facets(mesh)).all()
    free = np.setdiff1d(np.arange(basis.N), clamped)
    return Elasticity(mesh=mesh, basis=basis, lame=(lam, mu), K=K, F=F, free=free)


def count_free_dofs(scene: Scene, mesh: MeshTri) -> int:
    """The number of unknowns ``assemble_elasticity`` would give on ``mesh``, without
    assembling: two per vertex, none on a vertex of a clamped facet."""
    clamped = np.unique(mesh.facets[:, scene.dirichlet_facets(mesh)])
    return int(2 * (mesh.p.shape[1] - clamped.size))


def predict_uniform_free_dofs(scene: Scene, mesh: MeshTri) -> int:
    """``count_free_dofs`` of ``mesh.refined()``, without refining: uniform refinement adds one
    vertex per edge, and each clamped facet adds one clamped vertex (its midpoint)."""
    dirichlet = scene.dirichlet_facets(mesh)
    clamped = np.unique(mesh.facets[:, dirichlet]).size + dirichlet.size
    return int(2 * (mesh.p.shape[1] + mesh.facets.shape[1] - clamped))

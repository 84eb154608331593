"""Lagrange P_p (p = 1, 2, 3 on triangles; p = 1, 2 on tetrahedra) linear elasticity on
scikit-fem: stiffness, loads, stresses (docs/theory.md, sections 1, 9 and 14).

Plane stress uses lambda* = E nu / (1 - nu^2), plane strain lambda = E nu / ((1+nu)(1-2nu)).
Everything is vectorised over elements by scikit-fem's assembly.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
from scipy import sparse
from skfem import (
    Basis,
    ElementTetP1,
    ElementTetP2,
    ElementTriP1,
    ElementTriP2,
    ElementTriP3,
    ElementVector,
    FacetBasis,
    LinearForm,
    MeshTri,
    asm,
)
from skfem.helpers import dot
from skfem.models.elasticity import linear_elasticity

from formulations.dof_basis import DofBasis
from formulations.load import body_load
from formulations.p1_stiffness import p1_stiffness
from formulations.p2_stiffness import p2_stiffness
from formulations.tet_stiffness import tet_stiffness
from scenes import Scene
from scenes.base import is_integer
from scenes.topology import RefinementPlan, ensure_topology

ELEMENTS = {1: ElementTriP1, 2: ElementTriP2, 3: ElementTriP3}
ORDERS = tuple(ELEMENTS)
TET_ELEMENTS = {1: ElementTetP1, 2: ElementTetP2}  # scikit-fem has no P3 tetrahedron


def scalar_elements(dim: int) -> dict:
    """The scalar Lagrange elements by order on a mesh of dimension ``dim``."""
    return ELEMENTS if dim == 2 else TET_ELEMENTS


def order_descriptions() -> dict[str, str]:
    """One line per polynomial order, for ``python -m bench list``."""
    return {str(p): f"P{p} Lagrange displacements ({ELEMENTS[p].__name__}): energy error "
                    f"O(h^{p}) for smooth solutions" for p in ORDERS}


def check_order(order) -> int:
    """``order`` as an int, or a one-line refusal naming the allowed orders."""
    if not (is_integer(order) and int(order) in ELEMENTS):
        raise ValueError(f"order={order!r} is not one of {', '.join(map(str, ORDERS))}")
    return int(order)


def check_order_in(order, dim: int) -> int:
    """``check_order``, and refused in 3D above the orders tetrahedra have here."""
    order = check_order(order)
    if order not in scalar_elements(dim):
        raise ValueError(f"order={order!r} is not one of "
                         f"{', '.join(map(str, scalar_elements(dim)))} in {dim}D")
    return order


def why_no_element(order: int, dim: int) -> str | None:
    """Why there is no P_order element in ``dim`` dimensions here, or None."""
    if order in scalar_elements(dim):
        return None
    return (f"order {order} on {'triangles' if dim == 2 else 'tetrahedra'} is not available "
            f"(orders {', '.join(map(str, scalar_elements(dim)))})")


def vector_element(order: int = 1, dim: int = 2) -> ElementVector:
    """The displacement element: vector Lagrange P_order on triangles (tetrahedra in 3D)."""
    return ElementVector(scalar_elements(dim)[check_order_in(order, dim)]())


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
    order: int = 1

    @property
    def ndofs(self) -> int:
        """Number of unknowns (free DOFs)."""
        return int(self.free.size)

    @functools.cached_property
    def K_free(self) -> sparse.csr_matrix:
        """K on the free DOFs (built once)."""
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
        """Displacement at the mesh vertices, shape (d, n_vertices) (for every order: the
        vertex DOFs of a Lagrange element are the values there)."""
        return u[self.basis.nodal_dofs]

    def element_stress(self, u: np.ndarray) -> np.ndarray:
        """Stress (s11, s22, s12) per element at its centroid (the basis's rule); shape
        (3, n_elements) (P1: the constant stress of the element). On tetrahedra the six
        components (s11, s22, s33, s23, s13, s12)."""
        grad = self.basis.interpolate(u).grad[:, :, :, 0]
        if grad.shape[0] == 3:
            sigma = stress_tensor_from_gradient(grad, *self.lame)
            return np.array([sigma[0, 0], sigma[1, 1], sigma[2, 2], sigma[1, 2], sigma[0, 2],
                             sigma[0, 1]])
        return stress_from_gradient(grad, *self.lame)


def dof_basis(mesh: MeshTri, order: int = 1) -> Basis:
    """The displacement basis an ``Elasticity`` carries: its DOF numbering, element maps and
    element, on the one-point centroid rule (nothing integrates with it: each integral builds
    the basis of its own rule, and the quadrature data of a default basis cost more than K)."""
    return DofBasis(mesh, vector_element(order, mesh.dim()))


def element_diameters(mesh: MeshTri) -> np.ndarray:
    """Longest edge of every triangle or tetrahedron (h_T)."""
    p, k = mesh.p[:, mesh.t], mesh.t.shape[0]
    return np.max([np.linalg.norm(p[:, i] - p[:, j], axis=0)
                   for i in range(k) for j in range(i + 1, k)], axis=0)


def stress_tensor_from_gradient(grad: np.ndarray, lam: float, mu: float) -> np.ndarray:
    """sigma = lam tr(eps) I + 2 mu eps as the full (d, d, ...) tensor, in any dimension."""
    d = grad.shape[0]
    strain = 0.5 * (grad + np.swapaxes(grad, 0, 1))
    trace = np.trace(grad)
    return 2 * mu * strain + lam * trace * np.eye(d).reshape((d, d) + (1,) * (grad.ndim - 2))


def stress_from_gradient(grad: np.ndarray, lam: float, mu: float) -> np.ndarray:
    """sigma = lam tr(eps) I + 2 mu eps from grad[i, j] = d u_i / d x_j; returns (s11, s22, s12)."""
    e11, e22 = grad[0, 0], grad[1, 1]
    e12 = 0.5 * (grad[0, 1] + grad[1, 0])
    tr = e11 + e22
    return np.array([lam * tr + 2 * mu * e11, lam * tr + 2 * mu * e22, 2 * mu * e12])


def von_mises(stress: np.ndarray) -> np.ndarray:
    """Plane-stress von Mises stress sqrt(s11^2 + s22^2 - s11 s22 + 3 s12^2) (docs/theory.md,
    section 1); from the six 3D components (s11, s22, s33, s23, s13, s12),
    sqrt(((s11 - s22)^2 + (s22 - s33)^2 + (s33 - s11)^2) / 2 + 3 (s23^2 + s13^2 + s12^2))."""
    if len(stress) == 6:
        s11, s22, s33, s23, s13, s12 = stress
        return np.sqrt(((s11 - s22) ** 2 + (s22 - s33) ** 2 + (s33 - s11) ** 2) / 2
                       + 3 * (s23**2 + s13**2 + s12**2))
    s11, s22, s12 = stress
    return np.sqrt(s11**2 + s22**2 - s11 * s22 + 3 * s12**2)


def assemble_elasticity(scene: Scene, mesh: MeshTri, order: int = 1) -> Elasticity:
    """Stiffness K, load F = (f, v) + (q, v)_{Gamma_N}, and the free DOFs for ``mesh`` with
    P_order displacements."""
    order = check_order_in(order, mesh.dim())
    ensure_topology(mesh)
    basis = dof_basis(mesh, order)
    lam, mu = scene.material.lame
    if mesh.dim() == 3:  # local matrices on affine tetrahedra (formulations.tet_stiffness)
        K = tet_stiffness(basis, lam, mu)
    elif order == 1:  # constant strains: the closed-form local matrices (formulations.p1_stiffness)
        K = p1_stiffness(mesh, lam, mu)
    elif order == 2:  # the same straight into CSR (formulations.p2_stiffness)
        K = p2_stiffness(mesh, lam, mu)
    else:  # strain products have degree 2(p - 1): a rule of that order is exact
        stiffness_basis = Basis(mesh, basis.elem, intorder=2 * (order - 1))
        K = asm(linear_elasticity(lam, mu), stiffness_basis).tocsr()
    F = np.zeros(basis.N)
    if scene.body_force is not None:  # scikit-fem's default rule, of order 2p
        F += body_load(scene.body_force, Basis(mesh, basis.elem))
    neumann = scene.neumann_facets(mesh)
    if scene.traction is not None and neumann.size:
        @LinearForm
        def surface(v, w):
            return dot(scene.traction(w.x), v)

        F += asm(surface, FacetBasis(mesh, basis.elem, facets=neumann,
                                     intorder=max(4, 2 * order)))
    free = free_dofs(basis, scene.dirichlet_facets(mesh))
    return Elasticity(mesh=mesh, basis=basis, lame=(lam, mu), K=K, F=F, free=free, order=order)


def free_dofs(basis: Basis, dirichlet: np.ndarray) -> np.ndarray:
    """The DOFs not on a clamped facet, sorted."""
    is_free = np.ones(basis.N, dtype=bool)  # a mask, not a sorted set difference: O(N)
    is_free[basis.get_dofs(dirichlet).all()] = False
    return np.flatnonzero(is_free)


def lagrange_dofs(vertices: int, edges: int, triangles: int, order: int) -> int:
    """Scalar P_order DOFs of a mesh: one per vertex, p - 1 per edge, (p-1)(p-2)/2 inside."""
    return vertices + (order - 1) * edges + (order - 1) * (order - 2) // 2 * triangles


def count_free_dofs(scene: Scene, mesh: MeshTri, order: int = 1) -> int:
    """The number of unknowns ``assemble_elasticity`` would give on ``mesh``, without
    assembling: two per Lagrange node, none on a node of a clamped facet."""
    dirichlet = scene.dirichlet_facets(mesh)
    if mesh.dim() == 3:  # P1, P2: one node per vertex, p - 1 per edge
        clamped = (np.unique(mesh.facets[:, dirichlet]).size
                   + (order - 1) * np.unique(mesh.f2e[:, dirichlet]).size)
        return int(3 * (mesh.p.shape[1] + (order - 1) * mesh.edges.shape[1] - clamped))
    clamped = np.unique(mesh.facets[:, dirichlet]).size + (order - 1) * dirichlet.size
    nodes = lagrange_dofs(mesh.p.shape[1], mesh.facets.shape[1], mesh.t.shape[1], order)
    return int(2 * (nodes - clamped))


def predict_refined_free_dofs(scene: Scene, plan: RefinementPlan, order: int = 1) -> int:
    """``count_free_dofs`` of ``plan.refined`` without splitting a triangle: a red-green-blue
    split adds one vertex per split facet, which becomes two facets (two clamped ones on
    Gamma_D), and k triangles and k interior edges to a triangle with k split edges. A plan
    that scikit-fem carries out itself is counted after refining (uniform ones by
    ``predict_uniform_free_dofs``)."""
    mesh = plan.mesh
    if mesh.dim() == 3:
        return count_free_dofs(scene, plan.refined, order)
    if plan.split is None:
        return (predict_uniform_free_dofs(scene, mesh, order) if plan.marked is None
                else count_free_dofs(scene, plan.refined, order))
    dirichlet = scene.dirichlet_facets(mesh)
    new_vertices, more = plan.new_vertices(), int(plan.new_elements_per_element().sum())
    split_clamped = int(np.count_nonzero(plan.split[dirichlet]))
    clamped = (np.unique(mesh.facets[:, dirichlet]).size + split_clamped
               + (order - 1) * (dirichlet.size + split_clamped))
    nodes = lagrange_dofs(mesh.p.shape[1] + new_vertices,
                          mesh.facets.shape[1] + new_vertices + more, mesh.t.shape[1] + more,
                          order)
    return int(2 * (nodes - clamped))


def predict_uniform_free_dofs(scene: Scene, mesh: MeshTri, order: int = 1) -> int:
    """``count_free_dofs`` of ``mesh.refined()``, without refining: uniform refinement adds one
    vertex per edge, splits every edge in two and adds three inside every triangle (which
    becomes four); each clamped facet adds one clamped vertex and becomes two facets."""
    dirichlet = scene.dirichlet_facets(mesh)
    nv, ne, nt = mesh.p.shape[1], mesh.facets.shape[1], mesh.t.shape[1]
    clamped = (np.unique(mesh.facets[:, dirichlet]).size + dirichlet.size
               + (order - 1) * 2 * dirichlet.size)
    return int(2 * (lagrange_dofs(nv + ne, 2 * ne + 3 * nt, 4 * nt, order) - clamped))

"""Linear elasticity on scikit-fem for every cell family (``formulations.cells``): Lagrange
P_p on simplices, Q_p on quadrilaterals and hexahedra; stiffness, loads, stresses
(docs/theory.md, sections 1, 9, 14 and 15).

Plane stress uses lambda* = E nu / (1 - nu^2), plane strain lambda = E nu / ((1+nu)(1-2nu)).
Everything is vectorised over elements by scikit-fem's assembly. On a mesh with hanging nodes
the family's constraint P joins the cells: the unknowns are the conforming DOFs, the systems
P' K P and P' F (docs/theory.md, section 15.2).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
from scipy import sparse
from skfem import Basis, ElementVector, MeshTri

from formulations.cells import DEFAULT_CELL, family_for, family_of
from formulations.cells.dof_basis import DofBasis
from formulations.cells.triangle import TRIANGLES
from scenes import Scene
from scenes.base import is_integer
from scenes.topology import ensure_topology

ELEMENTS = TRIANGLES.elements
ORDERS = tuple(ELEMENTS)


def scalar_elements(dim: int, cell: str = DEFAULT_CELL) -> dict:
    """The scalar Lagrange elements by order of the family of ``cell`` in ``dim`` dimensions."""
    return family_for(cell, dim).elements


def order_descriptions() -> dict[str, str]:
    """One line per polynomial order, for ``python -m bench list``."""
    return {str(p): f"P{p} Lagrange displacements ({ELEMENTS[p].__name__}): energy error "
                    f"O(h^{p}) for smooth solutions" for p in ORDERS}


def check_order(order) -> int:
    """``order`` as an int, or a one-line refusal naming the allowed orders."""
    if not (is_integer(order) and int(order) in ELEMENTS):
        raise ValueError(f"order={order!r} is not one of {', '.join(map(str, ORDERS))}")
    return int(order)


def check_order_in(order, dim: int, cell: str = DEFAULT_CELL) -> int:
    """``check_order``, and refused above the orders the family has here."""
    order = check_order(order)
    why = family_for(cell, dim).why_no_element(order)
    if why is not None:
        raise ValueError(f"order={order!r}: {why}")
    return order


def why_no_element(order: int, dim: int, cell: str = DEFAULT_CELL) -> str | None:
    """Why there is no element of ``order`` on the cells of ``cell`` in ``dim`` dimensions."""
    return family_for(cell, dim).why_no_element(order)


def vector_element(order: int = 1, dim: int = 2, cell: str = DEFAULT_CELL) -> ElementVector:
    """The displacement element: vector Lagrange of ``order`` on the family's cells."""
    return ElementVector(scalar_elements(dim, cell)[check_order_in(order, dim, cell)]())


@dataclass(frozen=True, eq=False)
class Elasticity:
    """Assembled elasticity operator on one mesh. K and F are over the basis's DOFs (every
    cell DOF); ``constraint`` (None on conforming meshes) is P from the conforming DOFs to
    them, and ``free`` the conforming DOFs off Gamma_D (u = 0 there): the unknowns."""

    mesh: MeshTri
    basis: Basis
    lame: tuple[float, float]
    K: sparse.csr_matrix
    F: np.ndarray
    free: np.ndarray
    order: int = 1
    constraint: sparse.csr_matrix | None = None

    @property
    def ndofs(self) -> int:
        """Number of unknowns (free DOFs)."""
        return int(self.free.size)

    @functools.cached_property
    def _free_columns(self) -> sparse.csr_matrix | None:
        """P restricted to the free DOFs (None on conforming meshes)."""
        return None if self.constraint is None else self.constraint[:, self.free].tocsr()

    @functools.cached_property
    def K_free(self) -> sparse.csr_matrix:
        """K on the unknowns (built once): P_f' K P_f with hanging nodes."""
        if self.constraint is None:
            return self.K[self.free][:, self.free].tocsr()
        P = self._free_columns
        return (P.T @ self.K @ P).tocsr()

    @property
    def F_free(self) -> np.ndarray:
        """F on the unknowns: P_f' F with hanging nodes."""
        return self.on_unknowns(self.F)

    def on_unknowns(self, load: np.ndarray) -> np.ndarray:
        """A load over the basis's DOFs (l(phi_i) for every i) on the unknowns: P_f' l."""
        return load[self.free] if self.constraint is None else self._free_columns.T @ load

    def restrict(self, B: sparse.spmatrix) -> sparse.csr_matrix:
        """Rows over the basis's DOFs (contact constraints, traces) as rows over the
        unknowns: B P_f."""
        if self.constraint is None:
            return B.tocsr()[:, self.free].tocsr()
        return (B @ self._free_columns).tocsr()

    def expand(self, u_free: np.ndarray) -> np.ndarray:
        """Every DOF of the basis from the unknowns (zero on Gamma_D; P u with hanging
        nodes)."""
        if self.constraint is not None:
            return self._free_columns @ u_free
        u = np.zeros(self.basis.N)
        u[self.free] = u_free
        return u

    @functools.cached_property
    def rigid_modes(self) -> np.ndarray:
        """The rigid-body motions on the unknowns, (n, 3) in 2D or (n, 6) in 3D: the
        near-null space an algebraic multigrid needs (``rigid_body_modes``)."""
        return rigid_body_modes(self.basis)[self.free]

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
    element, on the one-point centroid rule of its cells (nothing integrates with it: each
    integral builds the basis of its own rule, and the quadrature data of a default basis
    cost more than K)."""
    family = family_of(mesh)
    return DofBasis(mesh, ElementVector(family.elements[order]()), family.centroid_rule)


def rigid_body_modes(basis: Basis) -> np.ndarray:
    """The translations and the infinitesimal rotations about the DOFs' centroid at every DOF
    of a vector Lagrange basis (exact: the DOFs are point values, the motions linear)."""
    x = basis.doflocs - basis.doflocs.mean(axis=1, keepdims=True)
    components = basis.split_indices()
    d = len(components)
    pairs = [(0, 1)] if d == 2 else [(0, 1), (1, 2), (2, 0)]
    modes = np.zeros((basis.N, d + len(pairs)))
    for c, dofs in enumerate(components):
        modes[dofs, c] = 1.0
    for k, (a, b) in enumerate(pairs):  # u_a = -x_b, u_b = x_a
        modes[components[a], d + k] = -x[b, components[a]]
        modes[components[b], d + k] = x[a, components[b]]
    return modes


def element_diameters(mesh: MeshTri) -> np.ndarray:
    """h_T of every cell: its longest distance between two vertices."""
    return family_of(mesh).diameters(mesh)


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
    """Stiffness K, load F = (f, v) + (q, v)_{Gamma_N}, the free DOFs and (with hanging
    nodes) the constraint for ``mesh`` with the family's elements of ``order``."""
    family = family_of(mesh)
    order = check_order_in(order, mesh.dim(), family.cell)
    ensure_topology(mesh)
    basis = dof_basis(mesh, order)
    lam, mu = scene.material.lame
    K = family.stiffness(basis, lam, mu, order)
    F = np.zeros(basis.N)
    if scene.body_force is not None:
        F += family.body_load(scene.body_force, basis, order)
    neumann = scene.neumann_facets(mesh)
    if scene.traction is not None and neumann.size:
        F += family.traction_load(scene.traction, basis, neumann, order)
    constraint = family.constraint(basis)
    free = free_dofs(basis, scene.dirichlet_facets(mesh), constraint)
    return Elasticity(mesh=mesh, basis=basis, lame=(lam, mu), K=K, F=F, free=free, order=order,
                      constraint=constraint)


def free_dofs(basis: Basis, dirichlet: np.ndarray,
              constraint: sparse.csr_matrix | None = None) -> np.ndarray:
    """The DOFs (conforming ones, with a constraint) not on a clamped facet, sorted."""
    if constraint is None:
        is_free = np.ones(basis.N, dtype=bool)  # a mask, not a sorted set difference: O(N)
        is_free[basis.get_dofs(dirichlet).all()] = False
        return np.flatnonzero(is_free)
    fixed = np.zeros(basis.N)
    fixed[basis.get_dofs(dirichlet).all()] = 1.0
    return np.flatnonzero(np.asarray(constraint.T @ fixed).ravel() == 0)


def count_free_dofs(scene: Scene, mesh: MeshTri, order: int = 1) -> int:
    """The number of unknowns ``assemble_elasticity`` would give on ``mesh``, without
    assembling (the family counts them)."""
    return family_of(mesh).count_free_dofs(scene, mesh, order)


def predict_refined_free_dofs(scene: Scene, plan, order: int = 1) -> int:
    """``count_free_dofs`` of a refinement plan's mesh (``formulations.cells.base.Plan``),
    predicted without making it where the family can."""
    return plan.free_dofs(scene, order)

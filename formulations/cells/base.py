"""Cell families: what a kind of cell brings to every formulation, estimator and measurement
(docs/theory.md, section 15.4).

A family (triangles, tetrahedra, quadrilaterals, hexahedra) is one module that registers one
``CellFamily``: its Lagrange elements per order, the centroid rule of its reference cell, how
a scene's starting mesh is made of it, how it refines and how many unknowns a mesh has before
anything is assembled, its stiffness matrix and body load, and the hanging-node constraints
of its meshes (None where its meshes are conforming). Formulations, estimators and the bench
ask the family of a mesh (``family_of``) or of a run's ``cell`` axis (``family_for``) and
never branch on it.

The ``cell`` axis of the matrix names a shape, not a dimension: ``tri`` is the simplices
(triangles in 2D, tetrahedra in 3D), ``quad`` the tensor-product cells (quadrilaterals,
hexahedra).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy import sparse
from skfem import Basis, FacetBasis, LinearForm, asm
from skfem.helpers import dot

from scenes.registry import Registry

DEFAULT_CELL = "tri"

CELL_FAMILIES = Registry("cell family")


@dataclass(frozen=True, eq=False)
class Plan:
    """The next mesh of a refinement, made on first use (``refined``), and what it will have
    (``free_dofs``) without making it where the family can predict it."""

    family: Any
    mesh: Any
    marked: np.ndarray | None
    detail: Any = None  # the family's own plan (scenes.topology.RefinementPlan for simplices)

    @functools.cached_property
    def refined(self):
        return self.family.refined(self)

    def free_dofs(self, scene, order: int) -> int:
        return self.family.predict_free_dofs(scene, self, order)


class CellFamily:
    """The base every family derives from: the defaults are those of a conforming family whose
    meshes scikit-fem refines uniformly."""

    name: str = ""  # tri, tet, quad, hex
    cell: str = DEFAULT_CELL  # the matrix axis value (module docstring)
    dim: int = 2
    shape: str = ""  # the cells' name in messages: triangles, quadrilaterals, ...
    mesh_type: type = type(None)
    elements: dict = {}  # scalar Lagrange element class per order
    centroid_rule: tuple[np.ndarray, np.ndarray] = (np.zeros((2, 1)), np.ones(1))
    tensor_product: bool = False  # Q_p on mapped squares or cubes (else P_p on simplices)
    contact_boundary: str = "edges"  # the kind of facet Gamma_C is made of (a registered one)
    # the registered formulations run on these cells and answer for friction themselves (else
    # a scene with friction is refused here: the family's own formulations do not model it)
    friction: bool = False

    # --- elements ---------------------------------------------------------------------------
    def why_no_element(self, order: int) -> str | None:
        if order in self.elements:
            return None
        return (f"order {order} on {self.shape} is not available (orders "
                f"{', '.join(map(str, self.elements))})")

    def why_not(self, scene, strategy: str = "uniform") -> str | None:
        """Why this family cannot run ``scene`` with ``strategy``, or None."""
        if scene.friction.active and not self.friction:
            return (f"friction on {self.shape} is not built (the scene's law is "
                    f"{scene.friction.label})")
        return self.why_no_mesh(scene) or self.why_no_contact()

    def why_no_mesh(self, scene) -> str | None:
        """Why ``scene`` has no starting mesh of this family, or None."""
        return None

    def why_no_contact(self) -> str | None:
        """Why the formulations cannot pose contact on this family's meshes (its contact
        boundary is not a registered one), or None."""
        from formulations.contact.boundary import CONTACT_BOUNDARIES

        if self.contact_boundary in CONTACT_BOUNDARIES.names():
            return None
        return (f"the contact boundary of {self.shape} ({self.contact_boundary}) is not "
                f"built; contact boundaries: {', '.join(CONTACT_BOUNDARIES.names())}")

    # --- meshes -----------------------------------------------------------------------------
    def starting_mesh(self, scene):
        return scene.mesh

    def refinement(self, mesh, marked: np.ndarray | None = None) -> Plan:
        return Plan(self, mesh, None if marked is None else np.asarray(marked))

    def refined(self, plan: Plan):
        return plan.mesh.refined() if plan.marked is None else plan.mesh.refined(plan.marked)

    def count_free_dofs(self, scene, mesh, order: int) -> int:
        raise NotImplementedError

    def predict_free_dofs(self, scene, plan: Plan, order: int) -> int:
        return self.count_free_dofs(scene, plan.refined, order)

    def diameters(self, mesh) -> np.ndarray:
        """The longest distance between two vertices of each cell (h_T)."""
        return vertex_diameters(mesh.p, mesh.t)

    # --- assembly ---------------------------------------------------------------------------
    def stiffness(self, basis, lam: float, mu: float, order: int) -> sparse.csr_matrix:
        from skfem.models.elasticity import linear_elasticity
        rule = Basis(basis.mesh, basis.elem, intorder=self.stiffness_intorder(order))
        return asm(linear_elasticity(lam, mu), rule).tocsr()

    def stiffness_intorder(self, order: int) -> int:
        return 2 * (order - 1)

    def body_load(self, body_force, basis, order: int) -> np.ndarray:
        @LinearForm
        def body(v, w):
            return dot(body_force(w.x), v)

        return asm(body, Basis(basis.mesh, basis.elem))

    def traction_load(self, traction, basis, facets: np.ndarray, order: int) -> np.ndarray:
        @LinearForm
        def surface(v, w):
            return dot(traction(w.x), v)

        return asm(surface, FacetBasis(basis.mesh, basis.elem, facets=facets,
                                       intorder=self.traction_intorder(order)))

    def traction_intorder(self, order: int) -> int:
        return max(4, 2 * order)

    def constraint(self, basis) -> sparse.csr_matrix | None:
        """P from the conforming DOFs to the basis's DOFs, or None (conforming meshes)."""
        return None

    def multiplier_groups(self, mesh, trace, h_over_H: float) -> np.ndarray | None:
        """The multiplier segment of each contact facet of ``trace`` from the mesh's own
        hierarchy (numbered along Gamma_C), or None where the meshes have none (the mixed
        method then groups the facets itself)."""
        return None

    def conforming(self, values: np.ndarray, basis) -> np.ndarray:
        """``values`` (..., basis.N) of a field given at every DOF, made conforming: kept at
        the conforming DOFs and interpolated by P at the others (unchanged on conforming
        meshes)."""
        return values


def vertex_diameters(p: np.ndarray, t: np.ndarray) -> np.ndarray:
    """The longest distance between two corners of each cell t (k, n) of points p (d, m)."""
    corners, k = p[:, t], t.shape[0]
    return np.max([np.linalg.norm(corners[:, i] - corners[:, j], axis=0)
                   for i in range(k) for j in range(i + 1, k)], axis=0)


def register_family(family: CellFamily, description: str) -> CellFamily:
    """Register ``family`` under its name (one line per family module)."""
    return CELL_FAMILIES.register(family.name, description, dim=family.dim)(family)


def families() -> list[CellFamily]:
    return [CELL_FAMILIES.get(name) for name in CELL_FAMILIES.names()]


def cell_names() -> list[str]:
    """The values of the ``cell`` axis."""
    return sorted({family.cell for family in families()})


def check_cell(cell) -> str:
    """``cell`` if some family has it, else a one-line refusal naming the allowed values."""
    if cell not in cell_names():
        raise ValueError(f"cell={cell!r} is not one of {', '.join(cell_names())}")
    return cell


def family_for(cell: str, dim: int) -> CellFamily:
    """The family of ``cell`` in ``dim`` dimensions; ValueError naming what exists."""
    check_cell(cell)
    for family in families():
        if family.cell == cell and family.dim == dim:
            return family
    raise ValueError(f"cell={cell!r} has no family in {dim}D")


def family_of(mesh) -> CellFamily:
    """The family whose meshes ``mesh`` is one of."""
    for family in families():
        if type(mesh) is family.mesh_type:
            return family
    raise ValueError(f"a {type(mesh).__name__} belongs to no cell family; families: "
                     f"{', '.join(CELL_FAMILIES.names())}")

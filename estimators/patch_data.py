"""The element data of the vertex-patch problems of the equilibrated stress (docs/theory.md,
section 13.2): RT_k element matrices, the right-hand sides psi_a sigma_h and the divergence data
sigma_h grad psi_a - psi_a f per (element, local vertex) pair, the load that balances patches
the discrete solution does not balance exactly.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from skfem import Basis, ElementDG, ElementTriP1, ElementTriP4, ElementVector
from skfem.quadrature import get_quadrature
from skfem.refdom import RefTri

from estimators.averaging import element_areas
from estimators.patch_classes import Classes, element_classes
from estimators.rt_reference import ReferenceRT, element_matrices, patch_rhs, scalar_values
from formulations.elasticity import ELEMENTS
from formulations.load import body_load
from formulations.p1_stiffness import barycentric_gradients

# scalar Lagrange triangles by degree, to P4: the load moments and the stream functions of
# ``estimators.symmetrisation`` use P_(k+1)
SCALARS = {**ELEMENTS, 4: ElementTriP4}


@dataclass(frozen=True, eq=False)
class Interior:
    """The element data of the patch problems (independent of the boundary data): the RT_k
    basis, sigma_h at its quadrature points (2, 2, n_el, nq), the element matrices (one per
    class of elements with equal ones), the pair right-hand sides rhs (n_el, 3, 2, n_rt) and
    divergence data (n_el, 3, 2, n_dg), per vertex sum_T int_T (sigma_h grad psi_a - psi_a f)
    (n_vertices, 2), and the degree k and the quadrature order used."""

    rt: ReferenceRT
    sigma_h: np.ndarray
    classes: Classes            # elements with equal matrices (``element_classes``)
    class_mass: np.ndarray      # (n_classes, n_rt, n_rt)
    class_divergence: np.ndarray  # (n_classes, n_dg, n_rt)
    rhs: np.ndarray
    data: np.ndarray
    total: np.ndarray
    k: int
    intorder: int


def interior_data(mesh, sigma_h, body_force, k: int, intorder: int) -> Interior:
    """``sigma_h(basis)`` returns sigma(u_h) (2, 2, n_el, nq) at the quadrature points of a
    basis; ``body_force`` f (2, ...) at points, or None; k the RT degree."""
    rt = ReferenceRT.build(mesh, k, intorder)
    X, W = rt.quadrature
    dg = scalar_values(ELEMENTS[k](), X)
    classes = Classes.of_owners(element_classes(mesh, k))  # few on refined meshes: each once
    mass, divergence = element_matrices(mesh, k, X, W, dg, classes.first)
    stress = sigma_h(rt)
    rhs, data = patch_rhs(mesh, k, X, W, dg, stress, barycentric_gradients(mesh)[0])
    if body_force is not None:
        data = data - load_moments(mesh, body_force, k)
    total = np.array([np.bincount(mesh.t.T.ravel(), data[:, :, r].sum(axis=-1).ravel(),
                                  minlength=mesh.p.shape[1]) for r in (0, 1)]).T
    return Interior(rt=rt, sigma_h=stress, classes=classes, class_mass=mass,
                    class_divergence=divergence, rhs=rhs,
                    data=data, total=total, k=k, intorder=intorder)


def load_moments(mesh, body_force, k: int) -> np.ndarray:
    """int_T f_r psi_a q_l per element, local vertex a, row r and P_k DG function q_l
    (n_el, 3, 2, n_dg), with the load rule of ``formulations.load`` (refined where f is rough,
    as for the load vector of the discrete problem): psi_a q_l is P_(k+1), so these are
    combinations of the P_(k+1) DG load entries with its values at the P_(k+1) nodes."""
    fine = SCALARS[k + 1]()
    basis = Basis(mesh, ElementVector(ElementDG(fine)), intorder=2 * k)
    F = body_load(body_force, basis)[basis.element_dofs]                  # (2 n_fine, n_el)
    per_node = F.reshape(-1, 2, mesh.t.shape[1])                           # node m, row r
    nodes = fine.doflocs.T
    hats, q = scalar_values(ElementTriP1(), nodes), scalar_values(ELEMENTS[k](), nodes)
    return np.einsum("mre,am,lm->earl", per_node, hats, q)


@dataclass(frozen=True, eq=False)
class BalancingLoad:
    """rho = sum_a nodal_a psi_a (``nodal`` (n_vertices, 2)) and ||rho||_{0,T}^2 per element."""

    nodal: np.ndarray
    squares: np.ndarray


def rebalanced(interior: Interior, defect: np.ndarray,
               clamped: np.ndarray) -> tuple[Interior, BalancingLoad]:
    """The patch data with the load rho = sum_a (defect_a / int psi_a) psi_a (off Gamma_D)
    added, so that every patch balances, and rho (docs/theory.md, 13.2): sum_T int_T (data)
    then equals the boundary fluxes for every vertex."""
    mesh = interior.rt.mesh
    area = element_areas(mesh)
    weight = np.bincount(mesh.t.ravel(), np.tile(area / 3, 3), minlength=mesh.p.shape[1])
    c = np.where(clamped[:, None], 0.0, defect / weight[:, None])      # (n_vertices, 2)
    local = c[mesh.t]                                                  # (3, n_el, 2)
    data = interior.data - np.einsum("ier,il,e->eirl", local, _hat_moments(interior.k), area)
    norm2 = area / 12 * ((local**2).sum(axis=0) + local.sum(axis=0) ** 2).sum(axis=-1)
    total = interior.total - np.where(clamped[:, None], 0.0, defect)
    return replace(interior, data=data, total=total), BalancingLoad(c, norm2)


def _hat_moments(k: int) -> np.ndarray:
    """int_T lambda_i q_l / |T| for the barycentric lambda_i and the P_k DG basis q_l, (3, n_dg)
    (the same on every triangle)."""
    X, W = get_quadrature(RefTri, k + 1)
    q, hats = scalar_values(ELEMENTS[k](), X), scalar_values(ElementTriP1(), X)
    return np.einsum("ap,lp,p->al", hats, q, W) / W.sum()

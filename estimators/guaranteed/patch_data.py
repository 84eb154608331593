"""The element data of the vertex-patch problems of the equilibrated stress (docs/theory.md,
section 13.2): RT_k element matrices, the right-hand sides psi_a sigma_h and the divergence data
sigma_h grad psi_a - psi_a f per (element, local vertex) pair, the load that balances patches
the discrete solution does not balance exactly.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from skfem import Basis, ElementDG, ElementTriP4, ElementVector
from skfem.quadrature import get_quadrature

from estimators.guaranteed.lagrange_tet import ElementTetDGP3
from estimators.guaranteed.patch_classes import Classes, element_classes
from estimators.guaranteed.rt_reference import (
    HATS,
    REFERENCE,
    ReferenceRT,
    element_matrices,
    patch_rhs,
    scalar_values,
)
from formulations.cells.load import body_load
from formulations.cells.p1_stiffness import barycentric_gradients
from formulations.elasticity import ELEMENTS, scalar_elements

# scalar Lagrange triangles by degree, to P4: the load moments and the stream functions of
# ``estimators.guaranteed.symmetrisation`` use P_(k+1)
SCALARS = {**ELEMENTS, 4: ElementTriP4}


def scalar_lagrange(degree: int, dim: int):
    """The scalar Lagrange element of ``degree`` on triangles (to P4) or tetrahedra (to P3;
    P3 discontinuous, ``estimators.guaranteed.lagrange_tet``)."""
    elements = {2: SCALARS, 3: {**scalar_elements(3), 3: ElementTetDGP3}}[dim]
    if degree not in elements:
        raise ValueError(f"degree={degree} has no Lagrange element on {dim}D simplices here "
                         f"(allowed: {sorted(elements)})")
    return elements[degree]()


@dataclass(frozen=True, eq=False)
class Interior:
    """The element data of the patch problems (independent of the boundary data): the RT_k
    basis, sigma_h at its quadrature points (d, d, n_el, nq), the element matrices (one per
    class of elements with equal ones), the pair right-hand sides rhs (n_el, d + 1, d, n_rt)
    and divergence data (n_el, d + 1, d, n_dg), per vertex sum_T int_T (sigma_h grad psi_a -
    psi_a f) (n_vertices, d), and the degree k and the quadrature order used."""

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
    """``sigma_h(basis)`` returns sigma(u_h) (d, d, n_el, nq) at the quadrature points of a
    basis; ``body_force`` f (d, ...) at points, or None; k the RT degree. On tetrahedra
    ``mesh`` lists every element's vertices in increasing order (``estimators.raviart_thomas_
    tet.sorted_tetrahedra``)."""
    rt = ReferenceRT.build(mesh, k, intorder)
    X, W = rt.quadrature
    d = mesh.dim()
    dg = scalar_values(scalar_lagrange(k, d), X)
    classes = Classes.of_owners(element_classes(mesh, k))  # few on refined meshes: each once
    mass, divergence = element_matrices(mesh, k, X, W, dg, classes.first)
    stress = sigma_h(rt)
    rhs, data = patch_rhs(mesh, k, X, W, dg, stress, barycentric_gradients(mesh)[0])
    if body_force is not None:
        data = data - load_moments(mesh, body_force, k)
    return Interior(rt=rt, sigma_h=stress, classes=classes, class_mass=mass,
                    class_divergence=divergence, rhs=rhs,
                    data=data, total=vertex_totals(mesh, data), k=k, intorder=intorder)


def vertex_totals(mesh, data: np.ndarray) -> np.ndarray:
    """sum_T int_T (data) per vertex a and row r (n_vertices, d) from the divergence data
    (n_el, d + 1, d, n_dg) (the P_k DG functions sum to 1)."""
    return np.array([np.bincount(mesh.t.T.ravel(), data[:, :, r].sum(axis=-1).ravel(),
                                 minlength=mesh.p.shape[1]) for r in range(mesh.dim())]).T


def load_moments(mesh, body_force, k: int) -> np.ndarray:
    """int_T f_r psi_a q_l per element, local vertex a, row r and P_k DG function q_l
    (n_el, d + 1, d, n_dg), with the load rule of ``formulations.cells.load`` (refined where f is
    rough, as for the load vector of the discrete problem): psi_a q_l is P_(k+1), so these are
    combinations of the P_(k+1) DG load entries with its values at the P_(k+1) nodes."""
    d = mesh.dim()
    fine = scalar_lagrange(k + 1, d)
    basis = Basis(mesh, ElementVector(ElementDG(fine)), intorder=2 * k)
    F = body_load(body_force, basis)[basis.element_dofs]                  # (d n_fine, n_el)
    per_node = F.reshape(-1, d, mesh.t.shape[1])                           # node m, row r
    nodes = fine.doflocs.T
    hats, q = scalar_values(HATS[d](), nodes), scalar_values(scalar_lagrange(k, d), nodes)
    return np.einsum("mre,am,lm->earl", per_node, hats, q)


@dataclass(frozen=True, eq=False)
class BalancingLoad:
    """rho = sum_a nodal_a psi_a (``nodal`` (n_vertices, d)) and ||rho||_{0,T}^2 per element."""

    nodal: np.ndarray
    squares: np.ndarray


def rebalanced(interior: Interior, defect: np.ndarray,
               clamped: np.ndarray) -> tuple[Interior, BalancingLoad]:
    """The patch data with the load rho = sum_a (defect_a / int psi_a) psi_a (off Gamma_D)
    added, so that every patch balances, and rho (docs/theory.md, 13.2): sum_T int_T (data)
    then equals the boundary fluxes for every vertex."""
    mesh = interior.rt.mesh
    area = barycentric_gradients(mesh)[1]
    corners = mesh.t.shape[0]
    weight = np.bincount(mesh.t.ravel(), np.tile(area / corners, corners),
                         minlength=mesh.p.shape[1])
    c = np.where(clamped[:, None], 0.0, defect / weight[:, None])      # (n_vertices, d)
    local = c[mesh.t]                                                  # (d + 1, n_el, d)
    data = interior.data - np.einsum("ier,il,e->eirl", local,
                                     hat_moments(interior.k, mesh.dim()), area)
    # int_T (sum_i c_i lambda_i)^2 = |T| (sum c_i^2 + (sum c_i)^2) / ((d + 1)(d + 2))
    norm2 = area / (corners * (corners + 1)) * ((local**2).sum(axis=0)
                                                + local.sum(axis=0) ** 2).sum(axis=-1)
    total = interior.total - np.where(clamped[:, None], 0.0, defect)
    return replace(interior, data=data, total=total), BalancingLoad(c, norm2)


def hat_moments(k: int, dim: int) -> np.ndarray:
    """int_T lambda_i q_l / |T| for the barycentric lambda_i and the P_k DG basis q_l,
    (d + 1, n_dg) (the same on every simplex)."""
    X, W = get_quadrature(REFERENCE[dim], k + 1)
    q, hats = scalar_values(scalar_lagrange(k, dim), X), scalar_values(HATS[dim](), X)
    return np.einsum("ap,lp,p->al", hats, q, W) / W.sum()

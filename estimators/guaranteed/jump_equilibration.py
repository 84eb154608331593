"""The oscillation of a body force that jumps inside elements, equilibrated on sub-triangles
(docs/theory.md, section 13.2, "Where f jumps").

sigma* balances Pi_k f, the P_k projection of f per element, and the bound charges the rest,
r = f - Pi_k f, through (r, v)_T <= (h_T / pi) ||r||_T ||grad v||_T. Where f jumps inside T,
r is O(1) on all of T, and this Poincare bound is several times the true dual norm of r (r is
orthogonal to P_k: it oscillates on T). On the elements where f is rough (those the load rule
of ``formulations.cells.load`` refines), each cut SUB_LEVELS times into 4^SUB_LEVELS sub-triangles
S,

    r = (f - Pi_S f) + (Pi_S f - Pi_k f) = r_1 + r_2,

Pi_S the P_k projection per sub-triangle. r_2 is a piecewise polynomial with zero mean on
every connected union of rough elements, so a tau in RT_k(S) with tau . n = 0 on the union's
boundary and div tau = r_2 exists; of these the one that minimises ||C^-1/2 sym tau||^2 +
C_K^2 ||skw tau||^2 is computed (one sparse saddle-point solve, the two rows coupled). Then
(r_2, v) = -(tau, grad v) <= ||C^-1/2 sym tau|| a(v, v)^1/2 + ||skw tau|| ||skw grad v|| <=
(||C^-1/2 sym tau|| + C_K ||skw tau||) a(v, v)^1/2, and r_1 is charged by the Poincare
bound on the sub-triangles, (h_S / pi) ||r_1||_S: a jump now costs only on the sub-triangles
it cuts, and at their size. Where the scene gives the jump line as a level set
(``Scene.load_jump``), the rough elements are refined CUT_SUB_LEVELS times and cut along it
(``estimators.guaranteed.level_set_cut``), and no sub-triangle holds a jump at all.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components
from scipy.sparse.linalg import splu
from skfem import Basis, ElementDG, ElementVector, MeshTri
from skfem.assembly import Dofs

from estimators.averaging import compliance_energy
from estimators.guaranteed.level_set_cut import cut_along
from estimators.guaranteed.local_korn import element_korn as korn_per_element
from estimators.guaranteed.patch_data import scalar_lagrange
from estimators.guaranteed.raviart_thomas import ElementTriRTk
from estimators.guaranteed.rt_reference import (
    ReferenceRT,
    element_matrices,
    orientations,
    reference_rt,
    scalar_values,
    summed_matrix,
)
from estimators.guaranteed.weighted_stress import energy_blocks, stress_weight, weighted_moments
from formulations.cells.load import MAX_DEPTH, body_load, refined_rule
from formulations.elasticity import ELEMENTS, element_diameters

SUB_LEVELS = 2  # each rough element in 16 sub-triangles
SUB_ADAPTIVE = 0  # then refinements of the sub-triangles f is rough on
# where the scene gives the jump as a level set, 4 sub-triangles, cut along it: within 4 % of
# 16 cut ones at P2 and P3 (21 % at P1, where the term is a few % of eta) at a quarter of
# their time, and 2 .. 3x below 16 uncut ones (docs/theory.md, 13.2)
CUT_SUB_LEVELS = 1


def sub_depth(levels: int) -> int:
    """The load rule's depth on the sub-triangles: down to the size it reaches on the
    elements."""
    return max(MAX_DEPTH - levels - SUB_ADAPTIVE, 1)


@dataclass(frozen=True, eq=False)
class JumpOscillation:
    """Per rough element (``elements``): ||C^-1/2 sym tau||_T^2, ||skw tau||_T^2 (of
    sigma* - tau - sigma_h if ``combined``) and the sub-triangles' Poincare term sum_S
    ((h_S / pi) ||r_1||_S)^2; ``divergence_defect`` the largest |div tau - r_2| moment
    relative to the largest r_2 moment (round-off)."""

    elements: np.ndarray
    symmetric: np.ndarray
    skew: np.ndarray
    remainder: np.ndarray
    divergence_defect: float
    combined: bool = False      # the terms of sigma* - tau - sigma_h, not of tau alone

    @property
    def osc_squares(self) -> np.ndarray:
        """osc_T^2 per rough element: the sub-triangles' Poincare term (tau's are A's)."""
        return self.remainder


def rough_elements(mesh, body_force, k: int) -> np.ndarray:
    """The elements on which the load rule refines (f jumps inside them), on triangles or
    tetrahedra."""
    if body_force is None:
        return np.zeros(0, dtype=np.int64)
    basis = Basis(mesh, ElementDG(scalar_lagrange(k, mesh.dim())), intorder=2 * k)
    return refined_rule(body_force, basis, max_depth=0)[0]


def jump_oscillation(mesh, body_force, k: int, lame: tuple[float, float], korn: float,
                     element_korn: np.ndarray | None = None, level_set=None,
                     stress_gap=None) -> JumpOscillation | None:
    """The terms of the module docstring on the rough elements of ``mesh`` (None if f is
    smooth on every element); ``korn`` C_K, the weight of the skew part. With
    ``element_korn`` (K_T per element of ``mesh``, ``estimators.guaranteed.local_korn``) the skew
    part of tau has zero mean on every rough element and weighs (K_T - 1) / (2 mu) there instead
    (docs/theory.md 13.4, "Local Korn constants"), and each sub-triangle's remainder is
    scaled by its own K_S over K_T (1 on similar ones; a cut piece's K_S is larger). With
    ``level_set`` (the scene's ``load_jump``) the sub-triangles are cut along the jump
    (``estimators.guaranteed.level_set_cut``). With ``stress_gap`` (sigma* - sigma_h at points x (2,
    n, nq) of elements ``cells`` of ``mesh``: ``stress_gap(x, cells)``, not with
    ``element_korn``) the terms are those of sigma* - tau - sigma_h on the rough elements,
    tau the minimiser of that weighted norm (``combined``; docs/theory.md 13.2, "tau inside
    A")."""
    if stress_gap is not None and element_korn is not None:
        raise ValueError("jump_oscillation: stress_gap is given, so element_korn must be None "
                         "(the combined terms use the global C_K)")
    rough = rough_elements(mesh, body_force, k)
    if rough.size == 0:
        return None
    sub, parent = sub_triangles(mesh, rough, body_force, k, level_set)
    rt = ReferenceRT.build(sub, k, 2 * k + 2)
    X, W = rt.quadrature
    dg_ref = ELEMENTS[k]()
    q = scalar_values(dg_ref, X)                             # (n_dg, nq)
    _, divergence = element_matrices(sub, k, X, W, q)
    depth = sub_depth(SUB_LEVELS if level_set is None else CUT_SUB_LEVELS)
    r_2, sub_coefficients = _split_load(mesh, rough, sub, parent, body_force, k, depth)
    if element_korn is None:
        weights, means = np.full(sub.t.shape[1], korn**2), None
    else:
        weights = ((element_korn[rough] - 1) / (2 * lame[1]))[parent]
        means = (_skew_means(sub, rt, parent, rough.size), parent)
    symmetric = energy_blocks(sub, k, X, W, stress_weight(lame, 0.0))
    skew_only = energy_blocks(sub, k, X, W, stress_weight(lame, 1.0)) - symmetric
    blocks = symmetric + weights[:, None, None] * skew_only
    gap = (None if stress_gap is None
           else stress_gap(np.asarray(rt.global_coordinates()), rough[parent]))
    target = None if gap is None else weighted_moments(rt, stress_weight(lame, korn), gap)
    tau, defect = _least_tau(sub, rt, blocks, divergence, r_2, means, target)
    values = rt.values(tau)                                  # (2, 2, n_sub, nq)
    if gap is not None:
        values = gap - values
    sym = np.array([values[0, 0], values[1, 1], 0.5 * (values[0, 1] + values[1, 0])])
    per = [(compliance_energy(sym, *lame) * rt.dx).sum(axis=1),
           ((values[0, 1] - values[1, 0]) ** 2 / 2 * rt.dx).sum(axis=1)]
    poincare = _remainders(rt, body_force, np.einsum("sml,lp->msp", sub_coefficients, q))
    if element_korn is not None:  # charged with K_T of the parent: K_S / K_T on each piece
        poincare *= korn_per_element(sub) / element_korn[rough][parent]
    per.append(poincare)
    symmetric, skew, remainder = (np.bincount(parent, p, rough.size) for p in per)
    return JumpOscillation(elements=rough, symmetric=symmetric, skew=skew,
                           remainder=remainder, divergence_defect=defect,
                           combined=gap is not None)


def _remainders(rt, body_force, projected: np.ndarray) -> np.ndarray:
    """((h_S / pi) ||r_1||_S)^2 per sub-triangle, r_1 = f - Pi_S f (``projected``, at the
    points of ``rt``, (2, n_sub, nq))."""
    f = body_force(np.asarray(rt.global_coordinates()))      # (2, n_sub, nq)
    r_1 = (((f - projected) ** 2).sum(axis=0) * rt.dx).sum(axis=1)
    return (element_diameters(rt.mesh) / np.pi) ** 2 * r_1


def sub_triangles(mesh, rough: np.ndarray, body_force, k: int, level_set=None
                  ) -> tuple[MeshTri, np.ndarray]:
    """The rough elements refined SUB_LEVELS times, then SUB_ADAPTIVE times where f is still
    rough, or, with ``level_set``, CUT_SUB_LEVELS times and cut along its zero set (a
    conforming mesh of their union), and the rough element (index into ``rough``) that holds
    each sub-triangle."""
    base = MeshTri(mesh.p, mesh.t[:, rough])
    sub = base.refined(SUB_LEVELS if level_set is None else CUT_SUB_LEVELS)
    for _ in range(SUB_ADAPTIVE):
        cut = rough_elements(sub, body_force, k)
        if cut.size == 0:
            break
        sub = sub.refined(cut)
    if level_set is not None:
        sub = cut_along(sub, level_set)
    centroids = sub.p[:, sub.t].mean(axis=1)
    return sub, base.element_finder()(*centroids)


def _split_load(mesh, rough, sub, parent, body_force, k, depth: int = sub_depth(SUB_LEVELS)):
    """The moments (f - ... , q_l)_S of r_2 = Pi_S f - Pi_k f against the sub-triangles' P_k
    DG functions (n_sub, 2, n_dg), and Pi_S f's nodal values (n_sub, 2, n_dg). Every integral
    of f is the load rule's (refined where f is rough), so Pi_k f is the projection that
    sigma* balances."""
    dg_ref = ELEMENTS[k]()
    basis = Basis(sub, ElementVector(ElementDG(dg_ref)), intorder=2 * k)
    n_sub = sub.t.shape[1]
    moments = body_load(body_force, basis, depth)[basis.element_dofs].reshape(-1, 2, n_sub)
    moments = moments.transpose(2, 1, 0)                               # (n_sub, 2, n_dg)
    X, W = basis.quadrature
    q = scalar_values(dg_ref, X)
    reference_mass = np.einsum("lp,mp,p->lm", q, q, W)
    det_sub = np.abs(sub.mapping().detA)
    own = np.linalg.solve(reference_mass, moments.transpose(2, 1, 0).reshape(q.shape[0], -1))
    own = own.reshape(q.shape[0], 2, n_sub).transpose(2, 1, 0) / det_sub[:, None, None]
    # the parent's P_k functions at the sub-triangles' DG nodes: exact on each S (degree k)
    nodes = sub.mapping().F(np.asarray(dg_ref.doflocs, dtype=float).T)  # (2, n_sub, n_dg)
    local = mesh.mapping().invF(nodes, tind=rough[parent])
    at_nodes = np.array([dg_ref.lbasis(local, j)[0] for j in range(q.shape[0])])  # l s m
    parent_moments = np.zeros((rough.size, 2, q.shape[0]))
    np.add.at(parent_moments, parent, np.einsum("lsm,srm->srl", at_nodes, moments))
    det_parent = np.abs(mesh.mapping().detA)[rough]
    coefficients = np.linalg.solve(reference_mass, parent_moments.transpose(2, 1, 0).reshape(
        q.shape[0], -1)).reshape(q.shape[0], 2, rough.size).transpose(2, 1, 0)
    coefficients /= det_parent[:, None, None]
    projected = np.einsum("srl,lsm->srm", coefficients[parent], at_nodes)
    r_2 = moments - np.einsum("lm,srm->srl", reference_mass, projected) * det_sub[:, None,
                                                                                    None]
    return r_2, own


def _skew_means(sub, rt, parent: np.ndarray, n_parents: int) -> sp.csr_matrix:
    """M (n_parents, 2 N): int_T s(tau) = int_T (tau_01 - tau_10) / 2 per rough element T
    for tau's two rows' RT DOFs, from int_S phi_j = o_j J int^ phi^_j (Piola)."""
    X, W = rt.quadrature
    phi, _ = reference_rt(rt.elem.k, X)
    integrals = np.einsum("cae,ja->ejc", sub.mapping().A, phi @ W)    # (n_sub, n_rt, c)
    integrals *= orientations(sub, phi.shape[0], rt.elem.k)[:, :, None]
    rows = np.repeat(parent, rt.element_dofs.shape[0])
    cols = rt.element_dofs.T.ravel()
    first = sp.csr_matrix((0.5 * integrals[:, :, 1].ravel(), (rows, cols)),
                          shape=(n_parents, rt.N))
    second = sp.csr_matrix((-0.5 * integrals[:, :, 0].ravel(), (rows, cols)),
                           shape=(n_parents, rt.N))
    return sp.hstack([first, second]).tocsr()


def _least_tau(sub, rt, blocks, divergence, data, means=None, target=None
               ) -> tuple[np.ndarray, float]:
    """tau (2, N) in RT_k(sub)^2, tau . n = 0 on the boundary, (div tau_r, q_l)_S = data
    (n_sub, 2, n_dg), of least (tau, tau)_W (``blocks``): [E B'; B 0] with one multiplier per
    row and connected component dropped (its equation follows from the data's zero mean).
    ``means`` (rows int_T s(tau) per parent T, ``_skew_means``): these vanish too, one per
    component dropped (their sum is the torque of the data, which is zero: r_2 is
    orthogonal to the rigid motions on every T). With ``target`` ((phi_j, g)_W, 2 N) the
    least ||g - tau||_W^2 instead."""
    n_sub, n_dg, n_rt = divergence.shape
    dofs = np.concatenate([rt.element_dofs, rt.element_dofs + rt.N]).T   # (n_sub, 2 n_rt)
    E = summed_matrix(blocks, dofs, 2 * rt.N)
    div_rows = (np.arange(n_sub)[:, None] * n_dg + np.arange(n_dg)).repeat(n_rt, axis=1)
    B = sp.csr_matrix((divergence.ravel(), (div_rows.ravel(),
                                            np.tile(rt.element_dofs.T, (1, n_dg)).ravel())),
                      shape=(n_sub * n_dg, rt.N))
    boundary = Dofs(sub, ElementTriRTk(rt.elem.k)).get_facet_dofs(sub.boundary_facets())
    free = np.setdiff1d(np.arange(rt.N), boundary.flatten())
    inner = sub.f2t[1] >= 0
    adjacency = sp.csr_matrix((np.ones(inner.sum()), (sub.f2t[0, inner], sub.f2t[1, inner])),
                              shape=(n_sub, n_sub))
    _, component = connected_components(adjacency, directed=False)
    kept = np.setdiff1d(np.arange(n_sub * n_dg),
                        np.unique(component, return_index=True)[1] * n_dg)
    Bf = B[kept][:, free]
    both = np.concatenate([free, free + rt.N])
    constraints = sp.block_diag([Bf, Bf])
    if means is not None:
        matrix, parent = means
        owner = np.zeros(matrix.shape[0], dtype=np.int64)
        owner[parent] = component
        held = np.setdiff1d(np.arange(matrix.shape[0]), np.unique(owner, return_index=True)[1])
        constraints = sp.vstack([constraints, matrix[held][:, both]])
    K = sp.bmat([[E[both][:, both], constraints.T], [constraints, None]], format="csc")
    flat = data.transpose(0, 2, 1).reshape(-1, 2)                      # (s l, r)
    linear = np.zeros(both.size) if target is None else target[both]
    rhs = np.concatenate([linear, flat[kept, 0], flat[kept, 1],
                          np.zeros(constraints.shape[0] - 2 * kept.size)])
    x = splu(K).solve(rhs)
    tau = np.zeros((2, rt.N))
    tau[:, free] = x[:both.size].reshape(2, -1)
    defect = np.abs(B @ tau.T - flat).max() / max(np.abs(flat).max(), np.finfo(float).tiny)
    return tau, float(defect)

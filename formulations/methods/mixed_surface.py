"""The mixed method on a 3D contact surface of triangles (docs/theory.md, sections 14.7 and
19.2): lambda_H on the contact surface one level coarser (``formulations.contact.
coarse_surface``), as the seed's T_{C,H} is in 2D.

* degree 1 (the default): lambda_H continuous and piecewise linear on the coarse surface,
  lambda_H = sum_Z lambda_Z psi_Z with the coarse hats psi_Z >= 0; rows
  B_Z j = int psi_Z phi_j . n ds, G_Z = int psi_Z g ds, and lambda_H >= 0 wherever its
  coefficients are (the sign condition of M_H^+ is the coefficients'). For P1 the coarse
  surface is one level coarser than the trace mesh (h/H = 1/2); for P2, whose Lagrange
  lattice is the trace mesh refined once, it is the trace mesh itself (h/H = 1).
* degree 0: lambda_H piecewise constant on the coarse triangles (four fine ones on a
  uniformly refined mesh); rows B_P j = int_P phi_j . n ds, G_P = int_P g ds. Its beta_h
  decays (the coarse triangles have no interior vertex, measured in docs/theory.md, 19.2).

``h_over_H = 1`` puts either on the trace mesh itself (degree 0 on it has beta_h = 0);
``multiplier_mesh = "star"`` takes the vertex-star patches (degree 0,
``formulations.contact.patches``). Friction keeps a tangential multiplier constant on each
patch, so a scene with friction takes degree 0 on stars.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import sparse

from formulations.base import ContactQP, DiscreteSolution, QPSolution, Residuals
from formulations.cells.evaluation import drop_roundoff, normal_trace_matrix
from formulations.contact import contact_trace
from formulations.contact.coarse_surface import coarse_hats, coarse_triangles, coarse_vertices
from formulations.contact.patches import free_normal_vertices, patch_sizes, patch_sum, patches
from formulations.discretisation import Discretisation, discrete_solution
from formulations.elasticity import assemble_elasticity, check_order
from formulations.friction.mixed import surface_friction_rows, surface_friction_state
from formulations.kkt import count_active
from scenes import Scene
from scenes.base import is_number

GAP_RULE_DEGREE = 6  # G = int psi g: g is smooth on each triangle; a rule exact to degree 6
MULTIPLIER_MESHES = ("coarse", "star")


@dataclass(frozen=True, eq=False)
class MixedDetails:
    """The mixed method's own arrays: the multiplier segment (3D: patch, the coarse
    triangle) of every contact facet."""

    segment_of_facet: np.ndarray


@dataclass(frozen=True)
class SurfaceSpace:
    """The 3D multiplier space: ``degree`` q, ``h_over_H`` (0.5: the surface one level
    coarser, 1: the contact triangles) and ``mesh`` ("coarse" or "star")."""

    degree: int
    h_over_H: float
    mesh: str


def surface_space(scene: Scene, h_over_H, order: int, multiplier_degree,
                  multiplier_mesh) -> SurfaceSpace:
    """The 3D options with their defaults (docs/theory.md, 19.2), checked (one-line errors).
    Without friction: q = 1 on the surface one level coarser than the trace's Lagrange
    lattice (P1: the coarse surface, h/H = 1/2; P2, whose lattice is the trace mesh refined
    once: the trace mesh, h/H = 1). With friction: q = 0 on vertex stars."""
    friction = scene.friction.active
    mesh = ("star" if friction else "coarse") if multiplier_mesh is None else multiplier_mesh
    if mesh not in MULTIPLIER_MESHES:
        raise ValueError(f"multiplier_mesh={multiplier_mesh!r} is not one of "
                         f"{', '.join(MULTIPLIER_MESHES)}")
    only_constant = friction or mesh == "star"
    degree = (0 if only_constant else 1) if multiplier_degree is None else multiplier_degree
    allowed = (0,) if only_constant else (0, 1)
    if degree not in allowed:
        why = " with friction" if friction else (
            f" with multiplier_mesh={multiplier_mesh!r}" if only_constant else "")
        raise ValueError(f"multiplier_degree={multiplier_degree!r} is not allowed on a 3D "
                         f"contact surface{why}: {' or '.join(map(str, allowed))}")
    if h_over_H is None:
        h_over_H = 1.0 if degree == 1 and order >= 2 else 0.5
    if not (is_number(h_over_H) and h_over_H in (0.5, 1.0)):
        raise ValueError(f"h_over_H={h_over_H!r} is not allowed on a 3D contact surface: 0.5 "
                         f"(the surface one level coarser) or 1 (the contact triangles)")
    return SurfaceSpace(int(degree), float(h_over_H), mesh)


def surface_patches(surface, mesh, elasticity, space: SurfaceSpace):
    """(patch of every contact triangle, coarse-vertex mask): the coarse triangles, the
    triangles themselves (h_over_H = 1) or the vertex stars."""
    coarse = coarse_vertices(surface.vertices, mesh.p.shape[1])
    if space.h_over_H == 1.0:
        coarse[np.unique(surface.vertices)] = True
        return patches(surface, "triangle", None), coarse
    if space.mesh == "star":
        admissible = free_normal_vertices(surface, elasticity.basis.nodal_dofs,
                                          elasticity.free)
        return patches(surface, "star", admissible), coarse
    return coarse_triangles(surface.vertices, coarse), coarse


def hat_weights(surface, P: sparse.csr_matrix, t: np.ndarray, w: np.ndarray):
    """W with (W v)_Z = int psi_Z v ds for v given at the points t of every facet (column
    f * nq + q): the fine hats are the barycentric coordinates (1 - t0 - t1, t0, t1)."""
    bary = np.array([1.0 - t[0] - t[1], t[0], t[1]])  # (3, nq)
    nf, nq = surface.size, t.shape[1]
    vals = bary[:, None, :] * (surface.measure[:, None] * w[None, :])[None]  # (3, nf, nq)
    rows = np.broadcast_to(surface.vertices[:, :, None], vals.shape)
    cols = np.broadcast_to(np.arange(nf * nq).reshape(nf, nq)[None], vals.shape)
    fine = sparse.csr_matrix((vals.ravel(), (rows.ravel(), cols.ravel())),
                             shape=(P.shape[0], nf * nq))
    return (P.T @ fine).tocsr()


def hat_pressure(surface, P: sparse.csr_matrix, lam: np.ndarray):
    """tt -> lambda_H at local coordinates tt of every facet: the fine nodal values P lambda,
    interpolated linearly on each facet."""
    nodal = P @ lam

    def pressure(tt):
        tt = np.asarray(tt, dtype=float)
        bary = np.array([1.0 - tt[0] - tt[1], tt[0], tt[1]])
        return np.einsum("kf,kt->ft", nodal[surface.vertices], bary)

    return pressure


def patch_rows(scene, elasticity, surface, patch: np.ndarray):
    """Degree 0: (B on all DOFs, G, row_scale, gram, row coordinates, the patch weights)."""
    t, w = surface.rule(elasticity.order)  # phi_j . n has degree p on a flat triangle
    tg, wg = surface.rule(GAP_RULE_DEGREE)
    gap = np.asarray(scene.gap(surface.points(tg))).ravel()
    area, H = patch_sizes(surface, patch)
    weights = patch_sum(patch, t.shape[1]) @ sparse.diags(np.outer(surface.measure, w).ravel())
    G = patch_sum(patch, tg.shape[1]) @ (gap * np.outer(surface.measure, wg).ravel())
    centroid = np.array([np.bincount(patch, weights=c * surface.measure) / area
                         for c in surface.coordinate.mean(axis=1)])
    # sum_P H_P ||mu||_{0,P}^2 = H_P |P| mu_P^2 (in 2D H_S^2, as |S| = H_S)
    return (weights @ normal_trace_matrix(elasticity.basis, surface, t), G, area, H * area,
            centroid, weights)


def hat_rows(scene, elasticity, surface, patch: np.ndarray, coarse: np.ndarray,
             P: sparse.csr_matrix):
    """Degree 1: (B on all DOFs, G, row_scale = int psi_Z, gram, row coordinates)."""
    t, w = surface.rule(elasticity.order + 1)  # psi_Z phi_j . n: degree p + 1
    tg, wg = surface.rule(GAP_RULE_DEGREE)
    B = hat_weights(surface, P, t, w) @ normal_trace_matrix(elasticity.basis, surface, t)
    G = hat_weights(surface, P, tg, wg) @ np.asarray(scene.gap(surface.points(tg))).ravel()
    # the weighted mass sum_T H_T int_T mu^2 of the coarse hats, H_T its coarse triangle's
    # size (in 2D H_S^2 times the Bernstein mass)
    tm, wm = surface.rule(2)
    integrals = hat_weights(surface, P, tm, wm)  # int psi_Z v over the points of rule tm
    H = patch_sizes(surface, patch)[1][patch]
    values = hat_weights(surface, P, tm, np.ones_like(wm)) @ sparse.diags(
        np.repeat(1.0 / surface.measure, tm.shape[1]))  # psi_Z at the points
    gram = (integrals @ sparse.diags(np.repeat(H, tm.shape[1])) @ values.T).tocsr()
    row_scale = np.asarray(integrals.sum(axis=1)).ravel()
    coordinate = np.asarray(scene.contact_coordinate(elasticity.mesh.p[:, coarse]))
    return B, G, row_scale, gram, coordinate


def discretise_surface(scene: Scene, mesh, h_over_H: float | None, order: int,
                       multiplier_degree: int | None,
                       multiplier_mesh: str | None = None) -> Discretisation:
    """The mixed method on tetrahedra (module docstring)."""
    space = surface_space(scene, h_over_H, check_order(order), multiplier_degree,
                          multiplier_mesh)
    elasticity = assemble_elasticity(scene, mesh, order)
    degree = space.degree
    surface = contact_trace(scene, mesh)
    patch, coarse = surface_patches(surface, mesh, elasticity, space)
    area = patch_sizes(surface, patch)[0]
    P = coarse_hats(surface.vertices, coarse) if degree else None
    friction = frame = None
    if degree:
        B, G, row_scale, gram, coordinate = hat_rows(scene, elasticity, surface, patch,
                                                     np.flatnonzero(coarse), P)
    else:
        B, G, row_scale, gram, coordinate, weights = patch_rows(scene, elasticity, surface,
                                                                patch)
        friction, frame = surface_friction_rows(
            scene, elasticity, surface, patch, weights, surface.rule(elasticity.order)[0],
            surface.rule(GAP_RULE_DEGREE))
    qp = ContactQP(K=elasticity.K_free, F=elasticity.F_free,
                   B=drop_roundoff(elasticity.restrict(B)), G=G, row_scale=row_scale,
                   objective_scale=float(scene.material.young_modulus),
                   near_null=elasticity.rigid_modes, friction=friction)

    def recover(answer: QPSolution, residuals: Residuals, status: str,
                reason: str) -> DiscreteSolution:
        lam = np.maximum(answer.multipliers, 0.0)
        pressure = (hat_pressure(surface, P, lam) if degree else lambda tt: np.repeat(
            lam[patch][:, None], np.shape(tt)[-1], axis=1))
        return discrete_solution(
            "mixed", elasticity, surface, answer, residuals, status, reason, u_free=answer.u,
            pressure=pressure, multiplier_breaks=np.zeros(0),
            active_constraints=count_active(qp, answer.u, lam),
            max_h_over_H=float(np.sqrt(surface.measure / area[patch]).max()),
            details=MixedDetails(segment_of_facet=patch),
            friction=None if friction is None else surface_friction_state(
                friction, answer.u, lam, answer.tangential, coordinate, patch, frame))

    return Discretisation(formulation="mixed", elasticity=elasticity, trace=surface, qp=qp,
                          recover=recover, row_coordinate=coordinate, multiplier_gram=gram)

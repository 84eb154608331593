"""Trace and Friedrichs constants with a proof, from the domain's geometry (docs/theory.md,
section 13.4, "Trace and Friedrichs constants with a proof").

For a convex polygon Omega, c its centroid, every v in H^1(Omega)^2 with v = 0 on Gamma_D
splits as v = w + r, r the rigid motion with the mean and the mean rotation of v, so that

* ||grad w|| <= K^(1/2) ||eps(v)||: Kim's Korn inequality for w (zero mean rotation), with
  K = 2 / sin^2(theta / 2), theta the Horgan-Payne angle of Omega seen from c
  (``estimators.guaranteed.local_korn``);
* ||w|| <= P ||grad w||, P = diam(Omega) / pi: Payne and Weinberger's Poincare inequality on
  a convex domain (w has zero mean);
* ||w||_(dOmega) <= T ||grad w||, T^2 = (2 / m) (P^2 + R P): int_(dOmega) w^2 (x - c) . n =
  int_Omega (2 w^2 + 2 w (x - c) . grad w), with m = min (x - c) . n > 0 over the boundary
  and R = max |x - c|;
* r = -w on Gamma_D, and on the three-dimensional space of rigid motions
  ||r||_Omega <= g_O ||r||_(Gamma_D) and ||r||_(Gamma_C) <= g_C ||r||_(Gamma_D), g^2 the
  largest eigenvalues of their Gram matrices (integrals of quadratics, computed exactly).

With a(v, v) >= s ||eps(v)||^2, s = 2 mu + 2 min(lambda, 0):

    C_F <= (P + g_O T) (K / s)^(1/2),    C_T <= (1 + g_C) T (K / s)^(1/2).

``estimators.guaranteed.chained_constants`` proves the same two on any triangulated domain, chaining
the rigid motions of its triangles to Gamma_D; each bound holds, so the smaller is taken
(the whole domain's on the rectangles of the built-in scenes, the chain's on thin or
non-convex ones).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.linalg import eigh

from estimators.averaging import element_areas
from estimators.guaranteed.chained_constants import (
    chained_constants,
    rigid_at,
    side_rule,
    strain_floor,
    triangle_rule,
)
from estimators.guaranteed.local_korn import edge_angle, korn_from_angle


@dataclass(frozen=True)
class ProvedConstants:
    trace: float        # C_T: the smaller of the two below
    friedrichs: float   # C_F
    convex: tuple[float, float] | None  # (C_T, C_F) of the whole domain, if it is convex
    chained: tuple[float, float]        # (C_T, C_F) chained over the initial mesh


@dataclass(frozen=True)
class Outline:
    """The boundary facets (a, b), their inward unit normals and the owners' third vertices
    of a triangle mesh, with its centroid."""

    a: np.ndarray
    b: np.ndarray
    normal: np.ndarray
    inner: np.ndarray
    centroid: np.ndarray

    @staticmethod
    def of(mesh) -> Outline:
        boundary = mesh.boundary_facets()
        a, b = mesh.facets[:, boundary]
        third = mesh.t[:, mesh.f2t[0, boundary]].sum(axis=0) - a - b
        edge = mesh.p[:, b] - mesh.p[:, a]
        normal = np.array([edge[1], -edge[0]]) / np.linalg.norm(edge, axis=0)
        normal *= np.sign((normal * (mesh.p[:, third] - mesh.p[:, a])).sum(axis=0))
        x = mesh.p[:, mesh.t]
        area = element_areas(mesh)
        centroid = (x.mean(axis=1) * area).sum(axis=1) / area.sum()
        return Outline(mesh.p[:, a], mesh.p[:, b], normal, mesh.p[:, third], centroid)

    def convex(self) -> bool:
        """Every boundary vertex on the inner side of every boundary facet's line."""
        corners = np.hstack([self.a, self.b])
        height = self.normal.T @ corners - (self.normal * self.a).sum(axis=0)[:, None]
        return bool(height.min() >= -1e-12 * np.ptp(corners))


def rigid_gram(rule: tuple[np.ndarray, np.ndarray], centre: np.ndarray) -> np.ndarray:
    """int r_i . r_j (3, 3) of the rigid motions about ``centre`` by a quadrature ``rule``
    of ``estimators.guaranteed.chained_constants`` (exact: quadratics)."""
    points, weights = rule
    r = rigid_at(points, np.repeat(centre[:, None], points.shape[1], axis=1))
    return np.einsum("idmq,jdmq,mq->ij", r, r, weights)


_CACHE: dict[str, ProvedConstants] = {}


def proved_constants(scene) -> ProvedConstants:
    """C_T and C_F of ``scene`` (a triangle mesh): the smaller of the whole domain's (if
    convex) and the chained ones (cached per scene name and parameters)."""
    key = f"{scene.name}:{sorted(scene.parameters.items())!r}"
    if key not in _CACHE:
        convex = convex_constants(scene) if Outline.of(scene.mesh).convex() else None
        chained = chained_constants(scene, scene.mesh)
        both = [pair for pair in (convex, chained) if pair is not None]
        _CACHE[key] = ProvedConstants(min(p[0] for p in both), min(p[1] for p in both),
                                      convex, chained)
    return _CACHE[key]


def convex_constants(scene) -> tuple[float, float]:
    """(C_T, C_F) of the module docstring for a convex domain."""
    mesh, outline = scene.mesh, Outline.of(scene.mesh)
    c = outline.centroid
    centres = np.repeat(c[:, None], outline.a.shape[1], axis=1)
    korn = float(korn_from_angle(edge_angle(outline.a, outline.b, centres, outline.inner).min()))
    m = float((outline.normal * (c[:, None] - outline.a)).sum(axis=0).min())
    corners = np.hstack([outline.a, outline.b])
    radius = float(np.linalg.norm(corners - c[:, None], axis=0).max())
    diameter = float(np.linalg.norm(corners[:, :, None] - corners[:, None, :], axis=0).max())
    poincare = diameter / np.pi
    boundary = np.sqrt(2 / m * (poincare**2 + radius * poincare))
    clamped = rigid_gram(side_rule(mesh, scene.dirichlet_facets(mesh)), c)
    rigid_domain = np.sqrt(eigh(rigid_gram(triangle_rule(mesh), c), clamped,
                                eigvals_only=True).max())
    contact = rigid_gram(side_rule(mesh, scene.contact_facets(mesh)), c)
    rigid_contact = np.sqrt(max(eigh(contact, clamped, eigvals_only=True).max(), 0.0))
    scale = np.sqrt(korn / strain_floor(scene.material.lame))
    return (float((1 + rigid_contact) * boundary * scale),
            float((poincare + rigid_domain * boundary) * scale))

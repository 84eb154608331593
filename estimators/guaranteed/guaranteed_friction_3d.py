"""The friction terms of the guaranteed bound on tetrahedra under Tresca friction
(docs/theory.md, 17.5, "On tetrahedra"): 17.5's bound with sigma*_t a tangential vector.

* sigma*_t is linear on each contact triangle: a start (sigma_t,h projected onto P1 per
  triangle, or zero) plus a continuous P1 vector correction delta, M delta = the tangential part
  of what u_h leaves unbalanced at the contact vertices off Gamma_D after lambda* (each
  component; M the P1 mass matrix of Gamma_C), each triangle's corner values then projected
  onto its plane. On a plane Gamma_C that projection changes nothing, and u_h balances every
  hat function in every direction; on a curved one what it leaves goes to rho (13.2). Of the
  two starts, the one with the smaller N_t + sqrt(B_t^+) (a third, within s at the corners
  by a cone program as on segments, lowered N_t by at most 10 %: docs/theory.md 17.5).
* N_t = C_Tt ||(|sigma*_t| - s)_+|| (C_Tt the tangential trace constant, 13.4) and B_t =
  int s |xi_h + d_t| + sigma*_t . (xi_h + d_t) + (|sigma*_t| - s)_+ |xi_h|, with |.| the
  length of a tangential vector, xi_h = (u_h - w)_t (w the obstacle's slide) and d_t the
  tangential part of the extension d.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import partial

import numpy as np
from scipy.sparse.linalg import splu

from estimators.guaranteed.contact_extension import vertex_normals
from estimators.guaranteed.contact_extension_3d import SurfaceExtension, corner_weights
from estimators.guaranteed.equilibration import BoundaryData
from estimators.guaranteed.guaranteed_contact import contact_mass
from estimators.guaranteed.guaranteed_contact_3d import (
    QUADRATURE_DEGREE,
    SurfaceTraction,
    local_weights,
    projected_corners,
    surface_balance,
    surface_traction,
    traction_balance,
)
from estimators.guaranteed.guaranteed_friction import FrictionBound
from formulations.cells.evaluation import evaluate_on_trace
from formulations.contact.reference_facets import triangle_rule


@dataclass(frozen=True, eq=False)
class SurfaceShear:
    """sigma*_t, linear on each contact triangle: ``corners`` (3, 3, n_f), its components at
    the triangle's corners (``ContactSurface.vertices`` order)."""

    corners: np.ndarray

    def __call__(self, t: np.ndarray) -> np.ndarray:
        """sigma*_t (3, n_f, nq) at local coordinates t (2, nq)."""
        return np.einsum("icf,cq->ifq", self.corners, corner_weights(t))

    def at(self, surface, x: np.ndarray) -> np.ndarray:
        """sigma*_t (3, n_f, nq) at points x (3, n_f, nq) of the contact triangles."""
        return np.einsum("cfq,icf->ifq", local_weights(surface, x), self.corners)


def in_plane(vectors: np.ndarray, normal: np.ndarray) -> np.ndarray:
    """The part of ``vectors`` (3, n_f, m) in the plane of each triangle (normal (3, n_f))."""
    n = normal[:, :, None]
    return vectors - (vectors * n).sum(axis=0) * n


def shear_balance(interior, surface, shear: SurfaceShear) -> np.ndarray:
    """int psi_a sigma*_t over Gamma_C per vertex, (n_vertices, 3)."""
    return surface_balance(interior, surface, lambda x: shear.at(surface, x))


def balanced_shear(surface, start: SurfaceShear, defect: np.ndarray,
                   clamped: np.ndarray) -> SurfaceShear:
    """``start`` plus delta, M delta = the tangential part of ``defect`` (n_vertices, 3) at the
    contact vertices off Gamma_D, in the triangles' planes."""
    nu = vertex_normals(surface)
    on = np.unique(surface.vertices)
    on = on[~clamped[on]]
    delta = np.zeros((3, surface.mesh.p.shape[1]))
    if on.size:
        rhs = defect[on] - (defect[on] * nu[:, on].T).sum(axis=1)[:, None] * nu[:, on].T
        delta[:, on] = splu(contact_mass(surface)[on][:, on].tocsc()).solve(rhs).T
    corners = (start.corners + delta[:, surface.vertices]).transpose(0, 2, 1)   # (3, n_f, 3)
    return SurfaceShear(in_plane(corners, surface.normal).transpose(0, 2, 1))


def friction_bound(scene, solution, shear: SurfaceShear, d: SurfaceExtension) -> FrictionBound:
    """N_t / C_Tt and B_t of the module docstring with the extension ``d``."""
    surface, law = solution.trace, scene.friction
    t, w = triangle_rule(QUADRATURE_DEGREE)
    at = evaluate_on_trace(solution.elasticity.basis, surface, t)
    u = at.value(solution.u).reshape(3, surface.size, w.size)
    xi = in_plane(u - law.slide_vector(3)[:, None, None], surface.normal)
    y = xi + d.tangential_part(surface, t)
    sigma = shear(t)
    bound = law.slip_bound_at(surface.points(t)).reshape(surface.size, w.size)
    excess = np.maximum(np.linalg.norm(sigma, axis=0) - bound, 0.0)
    per_facet = surface.integrate(bound * np.linalg.norm(y, axis=0) + (sigma * y).sum(axis=0)
                                  + excess * np.linalg.norm(xi, axis=0), w)
    per_element = np.bincount(surface.element, np.abs(per_facet), surface.mesh.t.shape[1])
    return FrictionBound(excess=float(np.sqrt(surface.integrate(excess**2, w).sum())),
                         complementarity=float(per_facet.sum()), per_element=per_element)


@dataclass(frozen=True, eq=False)
class SurfaceTractions:
    """lambda*, its contact terms with every extension, sigma*_t (None without friction) and
    the auxiliary problem's traction -lambda* n + sigma*_t on Gamma_C."""

    normal: SurfaceTraction
    bounds: tuple
    shear: SurfaceShear | None
    contact: BoundaryData

    def friction(self, scene, solution):
        """The friction terms as a function of the extension d (None without friction)."""
        return None if self.shear is None else partial(friction_bound, scene, solution,
                                                       self.shear)


def surface_tractions(scene, solution, interior, reaction: np.ndarray, clamped: np.ndarray,
                      trace_constant: float, shear_constant: float | None) -> SurfaceTractions:
    """lambda* (``estimators.guaranteed.guaranteed_contact_3d``, chosen with C_T =
    ``trace_constant``) for the normal balance net of sigma_t,h's own and, under friction, sigma*_t
    for what is left (module docstring; chosen with C_Tt = ``shear_constant``)."""
    surface = solution.trace
    starts = [] if solution.friction is None else [
        SurfaceShear(projected_corners(solution.friction.traction).transpose(1, 0, 2)),
        SurfaceShear(np.zeros((3, 3, surface.size)))]
    net = reaction - (shear_balance(interior, surface, starts[0]) if starts else 0.0)
    lam_star, bounds = surface_traction(scene, solution, interior, net, clamped, trace_constant)

    def normal(x):
        return -lam_star.at(surface, x)[None] * surface.normal[:, :, None]

    shear = None
    if starts:
        left = reaction - traction_balance(interior, surface, lam_star)

        def terms(candidate):  # N_t + sqrt(B_t^+), B_t the least over the extensions
            bound = [friction_bound(scene, solution, candidate, b.field) for b in bounds]
            return (shear_constant * bound[0].excess
                    + np.sqrt(max(min(b.complementarity for b in bound), 0.0)))

        shear = min((balanced_shear(surface, start, left - shear_balance(interior, surface,
                                                                          start), clamped)
                     for start in starts), key=terms)
    contact = BoundaryData(surface.facets, normal if shear is None else
                           lambda x: normal(x) + shear.at(surface, x))
    return SurfaceTractions(lam_star, bounds, shear, contact)

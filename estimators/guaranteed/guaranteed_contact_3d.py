"""The contact terms of the guaranteed bound on tetrahedra (docs/theory.md, section 14.5,
"`equilibrated` on tetrahedra"): lambda* and the extension d on the contact triangles.

* lambda* is linear on each contact triangle: a pressure (the formulation's lambda_h projected
  onto P1 per triangle, or zero) plus a continuous P1 correction delta with M delta = -R . nu
  on the contact vertices off Gamma_D (M the P1 mass matrix of Gamma_C, R the vertex reactions
  of u_h left by the pressure, nu the vertex normals), so that u_h balances every contact
  patch in the normal direction; of the two, the one with the smaller contact terms
  2 D + C_T ||lambda*_-|| + sqrt(B) over the extensions (as
  ``estimators.guaranteed.auxiliary_traction`` does on segments).
* the extensions d of ``estimators.guaranteed.contact_extension_3d``: with each the terms D,
||lambda*_-||
  and B (13.1).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.sparse.linalg import spsolve

from estimators.guaranteed.contact_extension import discrete_gap, vertex_normals
from estimators.guaranteed.contact_extension_3d import (
    EXTENSIONS_3D,
    SurfaceExtension,
    corner_weights,
)
from estimators.guaranteed.equilibration import BoundaryData, boundary_balance, boundary_fluxes
from estimators.guaranteed.guaranteed_contact import ContactBound, bound_of, contact_mass
from formulations.contact.reference_facets import triangle_rule

QUADRATURE_DEGREE = 8  # the rule on each contact triangle for lambda*_+ and the slack (kinked)
PROJECTION_DEGREE = 8  # the rule for projecting lambda_h onto P1 per triangle
# the P1 mass matrix of a triangle of area 1, in its corners' order
_MASS = (np.ones((3, 3)) + np.eye(3)) / 12.0


@dataclass(frozen=True, eq=False)
class SurfaceTraction:
    """lambda*, linear on each contact triangle: ``corners`` (3, n_f) its values at the
    triangle's corners (``ContactSurface.vertices`` order)."""

    corners: np.ndarray

    def __call__(self, t: np.ndarray) -> np.ndarray:
        """lambda* (n_f, nq) at local coordinates t (2, nq)."""
        return self.corners.T @ corner_weights(t)

    def at(self, surface, x: np.ndarray) -> np.ndarray:
        """lambda* (n_f, nq) at points x (3, n_f, nq) of the contact triangles."""
        return np.einsum("cfq,cf->fq", local_weights(surface, x), self.corners)


def local_weights(surface, x: np.ndarray) -> np.ndarray:
    """The P1 basis (3, n_f, nq) of each contact triangle at its points x (3, n_f, nq)."""
    a, b, c = (surface.mesh.p[:, v][:, :, None] for v in surface.vertices)
    e1, e2, r = b - a, c - a, x - a
    g11, g12, g22 = (e1 * e1).sum(0), (e1 * e2).sum(0), (e2 * e2).sum(0)
    r1, r2 = (r * e1).sum(0), (r * e2).sum(0)
    det = g11 * g22 - g12 * g12
    t0, t1 = (g22 * r1 - g12 * r2) / det, (g11 * r2 - g12 * r1) / det
    return np.array([1 - t0 - t1, t0, t1])


def projected_pressure(surface, pressure) -> SurfaceTraction:
    """The L2 projection of ``pressure(t)`` (n_f, nq) onto P1 per contact triangle."""
    return SurfaceTraction(projected_corners(pressure))


def projected_corners(values) -> np.ndarray:
    """The corner values (3, ..., n_f) of the L2 projection of ``values(t)`` (..., n_f, nq)
    onto P1 per contact triangle."""
    t, w = triangle_rule(PROJECTION_DEGREE)
    moments = np.einsum("...fq,q,cq->c...f", values(t), w, corner_weights(t))  # / area
    return np.tensordot(np.linalg.inv(_MASS), moments, axes=1)


def traction_balance(interior, surface, traction: SurfaceTraction) -> np.ndarray:
    """int psi_a (-lambda* n) over Gamma_C per vertex, (n_vertices, 3)."""
    return surface_balance(interior, surface, lambda x: -traction.at(surface, x)[None]
                           * surface.normal[:, :, None])


def surface_balance(interior, surface, values) -> np.ndarray:
    """int psi_a t over Gamma_C per vertex, (n_vertices, 3), for a traction t given by
    ``values(x)`` (3, n_f, nq) at points x of the contact triangles."""
    part = BoundaryData(surface.facets, values)
    return boundary_balance(interior.total.shape[0], boundary_fluxes(interior, [part]), 3)


def balanced(surface, traction: SurfaceTraction, defect: np.ndarray,
             clamped: np.ndarray) -> SurfaceTraction:
    """``traction`` plus delta, M delta = -defect . nu on the contact vertices off Gamma_D."""
    nu = vertex_normals(surface)
    on = np.unique(surface.vertices)
    on = on[~clamped[on]]
    delta = np.zeros(surface.mesh.p.shape[1])
    if on.size:
        rhs = -(defect[on] * nu[:, on].T).sum(axis=1)
        delta[on] = np.atleast_1d(spsolve(contact_mass(surface)[on][:, on].tocsc(), rhs))
    return SurfaceTraction(traction.corners + delta[surface.vertices])


def surface_bound(surface, traction: SurfaceTraction, d: SurfaceExtension, energy: np.ndarray,
                  room: np.ndarray) -> ContactBound:
    """D, ||lambda*_-|| and B (docs/theory.md, 13.1) of lambda* = ``traction`` and ``d``, with
    ``room`` = g - u_hn - d . n at the points of the rule of QUADRATURE_DEGREE."""
    t, w = triangle_rule(QUADRATURE_DEGREE)
    lam = traction(t)
    slack = surface.integrate(np.maximum(lam, 0.0) * room, w)
    return bound_of(surface, lam, surface.integrate(np.minimum(lam, 0.0) ** 2, w), slack, d,
                    energy)


def surface_traction(scene, solution, interior, reaction: np.ndarray, clamped: np.ndarray,
                     trace_constant: float) -> tuple[SurfaceTraction, tuple[ContactBound, ...]]:
    """lambda* of the module docstring and its contact terms with every extension of
    ``estimators.guaranteed.contact_extension_3d``."""
    surface = solution.trace
    pressures = [projected_pressure(surface, solution.pressure),
                 SurfaceTraction(np.zeros((3, surface.size)))]
    fields = [extend(scene, solution, clamped) for extend in EXTENSIONS_3D]
    energies = [d.energy(surface.mesh, solution.elasticity.lame, surface) for d in fields]
    t, _ = triangle_rule(QUADRATURE_DEGREE)
    gap = discrete_gap(scene, solution, t)           # once: every traction and field shares it
    rooms = [gap - d.normal_part(surface, t) for d in fields]
    best = None
    for pressure in pressures:
        defect = reaction - traction_balance(interior, surface, pressure)
        traction = balanced(surface, pressure, defect, clamped)
        bounds = tuple(surface_bound(surface, traction, d, energy, room)
                       for d, energy, room in zip(fields, energies, rooms, strict=True))
        terms = min(2 * b.extension + trace_constant * b.negative + np.sqrt(b.complementarity)
                    for b in bounds)
        if best is None or terms < best[0]:
            best = (terms, traction, bounds)
    return best[1], best[2]

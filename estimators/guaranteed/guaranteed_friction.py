"""The friction terms of the guaranteed bound under Tresca friction (docs/theory.md, 17.5).

The auxiliary problem takes the shear traction sigma*_t t on Gamma_C beside -lambda* n:
sigma*_t is sigma_t,h projected onto P_k per facet plus a continuous piecewise linear
correction that makes u_h balance every hat function along the vertex tangents (as lambda*
does along the normals, ``estimators.guaranteed.guaranteed_contact``). With s the slip bound, w the
obstacle's slide, xi_h = u_ht - w and d the extension of the contact terms, the bound of 13.1
gains

    N_t = C_Tt ||(|sigma*_t| - s)_+||_{0,Gamma_C}                      (added to a),
    B_t = int_{Gamma_C} s |xi_h + d_t| + sigma*_t (xi_h + d_t) + (|sigma*_t| - s)_+ |xi_h|
                                                                      (added to b).

Coulomb's law is not the optimality condition of a minimisation, and no such bound is claimed
for it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from estimators.guaranteed.contact_extension import Extension, vertex_normals
from estimators.guaranteed.guaranteed_contact import (
    ContactTraction,
    balanced_traction,
    projected_pressure,
    traction_at,
)
from estimators.guaranteed.strip_extension import StripExtension
from formulations.cells.evaluation import evaluate_on_trace
from formulations.contact.reference_facets import gauss_legendre
from formulations.friction.slack import contact_tangent

QUADRATURE = 10  # Gauss points per contact facet for the kinked integrands


@dataclass(frozen=True)
class FrictionBound:
    excess: float           # ||(|sigma*_t| - s)_+||_{0,Gamma_C}
    complementarity: float  # B_t
    per_element: np.ndarray  # |B_t| per element (its contact facets' shares)


def vertex_tangents(trace) -> np.ndarray:
    """The vertex normals turned by +90 degrees, (2, n_vertices): t at every contact vertex."""
    nu = vertex_normals(trace)
    return np.array([-nu[1], nu[0]])


def raw_shear(solution) -> ContactTraction:
    """sigma_t,h projected onto P_k per facet, without correction."""
    projected = projected_pressure(solution.friction.traction, solution.elasticity.order)
    return ContactTraction(pressure=projected, delta=np.zeros((2, solution.trace.size)))


def balanced_shear(solution, defect: np.ndarray, clamped: np.ndarray) -> ContactTraction:
    """sigma*_t: the projection plus the P1 correction of the tangential ``defect``."""
    return balanced_traction(solution.trace, raw_shear(solution).pressure, defect, clamped,
                             orientation=1.0, directions=vertex_tangents(solution.trace))


def shear_at(trace, shear: ContactTraction, x: np.ndarray) -> np.ndarray:
    """sigma*_t t at points x (2, n_f, nq) of the contact facets."""
    return traction_at(trace, shear, x, direction=contact_tangent(trace))


def shear_excess(scene, solution, shear: ContactTraction, t: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """sigma*_t, s and (|sigma*_t| - s)_+ at the points t of every contact facet, (n_f, nq)."""
    trace = solution.trace
    bound = scene.friction.slip_bound_at(trace.points(t)).reshape(trace.size, t.size)
    sigma = shear(t)
    return sigma, bound, np.maximum(np.abs(sigma) - bound, 0.0)


def friction_bound(scene, solution, shear: ContactTraction,
                   d: Extension | StripExtension) -> FrictionBound:
    """N_t / C_T and B_t of the module docstring; ``d`` the extension of the contact terms."""
    trace, law = solution.trace, scene.friction
    t, w = gauss_legendre(QUADRATURE)
    tangent = contact_tangent(trace)
    at = evaluate_on_trace(solution.elasticity.basis, trace, t)
    xi = (at.matrix(np.repeat(tangent, t.size, axis=1)) @ solution.u).reshape(
        trace.size, t.size) - law.slide
    y = xi + d.along(trace, tangent, t)
    sigma, bound, excess = shear_excess(scene, solution, shear, t)
    per_facet = trace.integrate(bound * np.abs(y) + sigma * y + excess * np.abs(xi), w)
    per_element = np.bincount(trace.element, np.abs(per_facet), trace.mesh.t.shape[1])
    return FrictionBound(excess=float(np.sqrt(trace.integrate(excess**2, w).sum())),
                         complementarity=float(per_facet.sum()), per_element=per_element)

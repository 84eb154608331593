"""The contact terms of the paper's (8), shared by every estimator.

w := (g - u_hn)_- on Gamma_C (minus the penetration).
* geometric term ||w||_{1/2,Gamma_C}^2, computed through the interpolation bound of the paper's
  Remark 2: ||w||_{1/2}^2 ~ ||w||_{0,Gamma_C} ||w||_{1,Gamma_C};
* complementarity term |(lambda_h, w)_{0,Gamma_C}|, with friction plus the friction
  complementarity of ``friction_complementarity``.

Per-element shares (for marking) are the facet-wise products ||w||_{0,e} ||w||_{1,e} rescaled to
sum to the global geometric term, and the facet-wise |(lambda_h, w)_e| (which sum exactly to the
global term since lambda_h >= 0 and w <= 0).

Units: the paper's ||w||'_{1/2} is an energy norm (inf ||v|| over extensions of w), which scales
like sqrt(E) times a length norm; we therefore weight ||w||_{1/2}^2 by Young's modulus E so that
every term of eta^2 is in energy units (for E = 1 it is the paper's term unchanged). The
complementarity term (a pressure times a length, integrated) already is.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from formulations import DiscreteSolution
from formulations.cells.evaluation import evaluate_on_trace

# w has kinks where u_hn crosses g inside a facet: the contact boundary's ``kink_degree`` (10
# Gauss points on an edge, 25 points on a triangle) keeps that quadrature error far below the
# discretisation error the term measures
# central difference step (relative to the facet) for the tangential derivative of g
_DT = 1e-6


@dataclass(frozen=True)
class ContactTerms:
    geometric: float          # E ||w||_{1/2}^2 (squared, energy units)
    complementarity: float    # |(lambda_h, w)| (already a square quantity)
    per_element: np.ndarray   # shares of geometric + complementarity per element


def tangential_derivatives(scene, trace, t: np.ndarray, gradient: np.ndarray) -> list:
    """d/dtau (g - u_hn) (n, nq) along each unit direction tau of the facets (the contact
    boundary's ``surface_tangents``): g by central differences, u_hn from grad u_h (d, d, n nq)
    exactly."""
    nq = t.shape[-1]
    normal = trace.at_points(trace.normal, nq)
    return [dg - np.einsum("in,ijn,jn->n", normal, gradient,
                           trace.at_points(tau, nq)).reshape(trace.size, nq)
            for dg, tau in zip(trace.gap_derivatives(scene, t, _DT), trace.surface_tangents(),
                               strict=True)]


def friction_complementarity(scene, solution: DiscreteSolution, at_points, t: np.ndarray,
                             w: np.ndarray) -> np.ndarray:
    """|int_e (s |u_th| + sigma_t,h . u_th) ds| per contact facet (docs/theory.md, 17.5): zero
    where the friction law holds pointwise (stick: u_th = 0; slip: sigma_t,h = -s u_th /
    |u_th|), with s the Tresca bound or mu lambda_h (Coulomb). In 3D u_th = u_h - u_hn n and
    sigma_t,h are vectors."""
    trace, law = solution.trace, scene.friction
    nq = t.shape[-1]
    normal = trace.at_points(trace.normal, nq)
    # relative to the obstacle, whose slide w is the contact boundary's
    u = at_points.value(solution.u) - trace.at_points(trace.slide_vector(law.slide), nq)
    u_t = u - np.einsum("in,in->n", u, normal) * normal
    size = np.linalg.norm(u_t, axis=0).reshape(trace.size, nq)
    shear = trace.shear_vector(solution.friction.traction(t))  # (d, n, nq)
    work = np.einsum("in,in->n", shear.reshape(shear.shape[0], -1), u_t).reshape(trace.size, nq)
    bound = (law.slip_bound_at(trace.points(t)) if law.kind == "tresca"
             else law.coefficient * solution.pressure(t))
    return np.abs(trace.integrate(bound * size + work, w))


def contact_terms(scene, solution: DiscreteSolution) -> ContactTerms:
    trace = solution.trace
    t, w = trace.rule(trace.kink_degree)
    at_points = evaluate_on_trace(solution.elasticity.basis, trace, t)
    nq = t.shape[-1]
    normal = trace.at_points(trace.normal, nq)
    u_n = np.einsum("in,in->n", at_points.value(solution.u), normal).reshape(trace.size, nq)
    g = scene.gap(trace.points(t))
    d = g - u_n
    inside = d < 0
    wval = np.where(inside, d, 0.0)
    # the tangential gradient of g - u_hn where it penetrates
    dw2 = sum(np.where(inside, dk, 0.0) ** 2 for dk in
              tangential_derivatives(scene, trace, t, at_points.gradient(solution.u)))

    l2 = trace.integrate(wval**2, w)
    h1 = l2 + trace.integrate(dw2, w)
    young = float(scene.material.young_modulus)
    geometric = young * float(np.sqrt(l2.sum() * h1.sum()))
    local_geo = np.sqrt(l2 * h1)
    if local_geo.sum() > 0:
        local_geo *= geometric / local_geo.sum()
    local_comp = np.abs(trace.integrate(solution.pressure(t) * wval, w))
    if solution.friction is not None:
        local_comp += friction_complementarity(scene, solution, at_points, t, w)
    n_elements = solution.elasticity.mesh.t.shape[1]
    per_element = np.bincount(trace.element, weights=local_geo + local_comp, minlength=n_elements)
    return ContactTerms(geometric=geometric, complementarity=float(local_comp.sum()),
                        per_element=per_element)

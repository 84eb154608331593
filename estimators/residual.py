"""``residual``: the paper's eta of (8) with the residual eta_0 of its section 5.

eta_0^2 = sum_T ( h_T^2 R_{0,T}^2 + sum_{e in E_T} h_e R_{0,e}^2 ),
R_{0,T} = ||f + div sigma(u_h)||_{0,T},
R_{0,e} = 1/2 ||[sigma_n(u_h)]||_e (interior), ||sigma_n(u_h) - q||_e (Gamma_N),
          ||sigma_nn(u_h) + lambda_h||_e + ||sigma_nt(u_h)||_e (Gamma_C), 0 on Gamma_D.
For P1, sigma(u_h) is constant per element, so div sigma(u_h) = 0 and the jumps are constant
along each edge. h_T is the element diameter, h_e the edge length.

Units: the residuals are stresses, so sum h^2 R^2 scales like E ||u - u_h||^2. We report
eta_0^2 = (1/E) sum_T (...) so that eta_0 is in energy-norm units and the effectivity index does
not depend on Young's modulus; for E = 1 this is exactly the paper's formula (its "<~" hides
material constants, so rates and marking are unaffected by the weight).
"""

from __future__ import annotations

import numpy as np
from skfem import Functional

from estimators.base import Estimate, combine, register_estimator
from estimators.contact_terms import contact_terms
from formulations import DiscreteSolution
from formulations.contact import gauss_legendre, outer_normals
from formulations.elasticity import element_diameters

EDGE_QUADRATURE_POINTS = 4


def _tensor(stress: np.ndarray) -> np.ndarray:
    s11, s22, s12 = stress
    return np.array([[s11, s12], [s12, s22]])


def element_residual(scene, solution: DiscreteSolution) -> np.ndarray:
    """h_T^2 ||f + div sigma(u_h)||_T^2 per element (div sigma(u_h) = 0 for P1)."""
    mesh = solution.elasticity.mesh
    n_elements = mesh.t.shape[1]
    if scene.body_force is None:
        return np.zeros(n_elements)
    diameter = element_diameters(mesh)
    f_squared = Functional(lambda w: (scene.body_force(w.x) ** 2).sum(axis=0))
    return diameter**2 * f_squared.elemental(solution.elasticity.basis)


def edge_residuals(scene, solution: DiscreteSolution) -> np.ndarray:
    """sum_{e in E_T} h_e R_{0,e}^2 per element."""
    mesh = solution.elasticity.mesh
    n_elements = mesh.t.shape[1]
    sigma = _tensor(solution.elasticity.element_stress(solution.u))  # (2, 2, n_elements)
    out = np.zeros(n_elements)

    interior = np.flatnonzero(mesh.f2t[1] >= 0)
    t1, t2 = mesh.f2t[:, interior]
    h, n = outer_normals(mesh, *mesh.facets[:, interior], t1)  # sign irrelevant for the jump
    jump = np.einsum("ijn,jn->in", sigma[:, :, t1] - sigma[:, :, t2], n)
    share = h * 0.25 * (jump**2).sum(axis=0) * h       # h_e (1/2 ||[sigma_n]||_e)^2
    out += np.bincount(t1, share, n_elements) + np.bincount(t2, share, n_elements)

    t, w = gauss_legendre(EDGE_QUADRATURE_POINTS)
    neumann = scene.neumann_facets(mesh)
    if neumann.size:
        element = mesh.f2t[0, neumann]
        h, n = outer_normals(mesh, *mesh.facets[:, neumann], element)
        sn = np.einsum("ijn,jn->in", sigma[:, :, element], n)[:, :, None]
        if scene.traction is not None:
            sn = sn - scene.traction(scene.facet_points(neumann, t, mesh))
        norm2 = ((sn**2).sum(axis=0) * w).sum(axis=1) * h
        out += np.bincount(element, h * norm2, n_elements)

    trace = solution.trace
    sn = np.einsum("ijn,jn->in", sigma[:, :, trace.element], trace.normal)
    snn = np.einsum("in,in->n", sn, trace.normal)
    snt = np.linalg.norm(sn - snn * trace.normal, axis=0)
    normal_part = np.sqrt(trace.integrate((snn[:, None] + solution.pressure(t)) ** 2, w))
    r_e = normal_part + snt * np.sqrt(trace.length)
    out += np.bincount(trace.element, trace.length * r_e**2, n_elements)
    return out


@register_estimator("residual", "residual eta_0 (seed paper, section 5) plus the geometric and "
                                "complementarity contact terms of eq. (8)")
def estimate(scene, solution: DiscreteSolution) -> Estimate:
    young = float(scene.material.young_modulus)
    eta0_local = (element_residual(scene, solution) + edge_residuals(scene, solution)) / young
    return combine("residual", eta0_local, contact_terms(scene, solution))

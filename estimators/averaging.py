"""``averaging``: stress recovery by nodal averaging (Zienkiewicz-Zhu; Bartels and Carstensen use
it for obstacle problems) plus the contact terms of the paper's (8).

A sigma_h is the continuous P1 field whose value at a vertex is the area-weighted mean of the
(constant) P1 stresses of the elements around it, and

    eta_A^2 = sum_T ||C^{-1/2} (sigma_h - A sigma_h)||_{0,T}^2,
    sigma : C^{-1} sigma = (sigma : sigma - lambda/(2 (lambda + mu)) (tr sigma)^2) / (2 mu)

with the 2D Lame constants of the scene (lambda* in plane stress). This is in energy-norm units
already (no weighting needed, unlike ``residual``). The integrand is quadratic on each triangle,
so the edge-midpoint rule integrates it exactly. eta_A is reported as ``eta_0`` (the volume part)
and the geometric and complementarity terms are the shared ``contact_terms``.
"""

from __future__ import annotations

import numpy as np

from estimators.base import Estimate, combine, register_estimator
from estimators.contact_terms import contact_terms
from formulations import DiscreteSolution


def element_areas(mesh) -> np.ndarray:
    p = mesh.p[:, mesh.t]
    a, b = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    return 0.5 * np.abs(a[0] * b[1] - a[1] * b[0])


def averaged_stress(mesh, stress: np.ndarray, area: np.ndarray) -> np.ndarray:
    """Vertex values (3, n_vertices) of A sigma_h from element stresses (3, n_elements)."""
    nv = mesh.p.shape[1]
    weight = np.bincount(mesh.t.ravel(), np.tile(area, 3), nv)
    return np.array([np.bincount(mesh.t.ravel(), np.tile(area * s, 3), nv) for s in stress]) \
        / weight


def compliance_energy(stress: np.ndarray, lam: float, mu: float) -> np.ndarray:
    """sigma : C^-1 sigma for stresses given as (s11, s22, s12, ...)."""
    s11, s22, s12 = stress
    trace = s11 + s22
    return (s11**2 + s22**2 + 2 * s12**2 - lam / (2 * (lam + mu)) * trace**2) / (2 * mu)


def averaging_indicators(solution: DiscreteSolution) -> np.ndarray:
    """||C^{-1/2}(sigma_h - A sigma_h)||_T^2 per element."""
    mesh = solution.elasticity.mesh
    lam, mu = solution.elasticity.lame
    stress = solution.elasticity.element_stress(solution.u)
    area = element_areas(mesh)
    vertex = averaged_stress(mesh, stress, area)[:, mesh.t]  # (3 components, 3 vertices, nT)
    total = np.zeros(area.size)
    for i, j in ((0, 1), (1, 2), (2, 0)):  # edge midpoints, weight area / 3 each
        difference = stress - 0.5 * (vertex[:, i] + vertex[:, j])
        total += compliance_energy(difference, lam, mu)
    return total * area / 3.0


@register_estimator("averaging", "Zienkiewicz-Zhu nodal stress averaging in the energy norm "
                                 "plus the geometric and complementarity contact terms of (8)")
def estimate(scene, solution: DiscreteSolution) -> Estimate:
    return combine("averaging", averaging_indicators(solution), contact_terms(scene, solution))

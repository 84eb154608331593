"""``averaging``: stress recovery by nodal averaging (Zienkiewicz-Zhu; Bartels and Carstensen use
it for obstacle problems) plus the contact terms of the paper's (8).

A sigma_h is the continuous P_p field (p the displacement order) whose value at a Lagrange node is
the area-weighted mean of the values of sigma_h there from the elements around it (for P1: the
constant stresses of the elements at a vertex), and

    eta_A^2 = sum_T ||C^{-1/2} (sigma_h - A sigma_h)||_{0,T}^2,
    sigma : C^{-1} sigma = (sigma : sigma - lambda/(2 (lambda + mu)) (tr sigma)^2) / (2 mu)

with the 2D Lame constants of the scene (lambda* in plane stress); on tetrahedra the same with
the nine stress entries and sigma : C^{-1} sigma = (sigma : sigma - lambda / (3 lambda + 2 mu)
(tr sigma)^2) / (2 mu), weights the elements' volumes. This is in energy-norm units
already (no weighting needed, unlike ``residual``). The integrand has degree 2p on each
triangle, integrated exactly. A sigma_h is one degree above sigma_h (degree p - 1), as for P1,
which is what lets it approximate sigma to the order sigma_h does (docs/theory.md, section 9).
eta_A is reported as ``eta_0`` (the volume part)
and the geometric and complementarity terms are the shared ``contact_terms``.
"""

from __future__ import annotations

from math import isqrt

import numpy as np
from skfem import Basis

from estimators.base import Estimate, combine, register_estimator
from estimators.contact_terms import contact_terms
from formulations import DiscreteSolution
from formulations.cells import family_of
from formulations.cells.evaluation import gradients_at_reference
from formulations.cells.p1_stiffness import barycentric_gradients
from formulations.elasticity import stress_from_gradient, stress_tensor_from_gradient


def element_areas(mesh) -> np.ndarray:
    return barycentric_gradients(mesh)[1]


def averaged_stress(solution: DiscreteSolution, scalar: Basis) -> np.ndarray:
    """The DOF values (3, scalar.N) of A sigma_h in the continuous scalar P_p space ``scalar``:
    at each Lagrange node, the area-weighted mean of the values of sigma_h at that node from
    the elements around it (for P1: of their constant stresses)."""
    elasticity = solution.elasticity
    mesh = elasticity.mesh
    grad = gradients_at_reference(elasticity.basis, solution.u, scalar.elem.doflocs.T)
    n_local = grad.shape[-1]
    stress = stresses(grad, elasticity.lame).reshape(-1, grad.shape[2] * n_local)
    dofs = scalar.element_dofs.T.ravel()  # element-major, as ``stress``
    weight = np.repeat(scalar.dx.sum(axis=1), n_local)  # the cells' areas (volumes)
    total = np.bincount(dofs, weight, scalar.N)
    mean = np.array([np.bincount(dofs, weight * s, scalar.N) for s in stress]) / total
    # with hanging nodes: the means at the conforming nodes, interpolated at the others
    return family_of(mesh).conforming(mean, scalar)



def stresses(grad: np.ndarray, lame: tuple[float, float]) -> np.ndarray:
    """sigma(grad) as (s11, s22, s12, ...) in 2D, as the nine tensor entries in 3D."""
    if grad.shape[0] == 3:
        sigma = stress_tensor_from_gradient(grad, *lame)
        return sigma.reshape((9,) + sigma.shape[2:])
    return stress_from_gradient(grad, *lame)


def compliance_energy(stress: np.ndarray, lam: float, mu: float) -> np.ndarray:
    """sigma : C^-1 sigma for stresses given as (s11, s22, s12, ...), or as all d^2 entries of
    a symmetric tensor (the nine in 3D): (sigma : sigma - lambda / (d lambda + 2 mu)
    (tr sigma)^2) / (2 mu)."""
    d = isqrt(len(stress))
    if d * d == len(stress):
        trace = sum(stress[i * (d + 1)] for i in range(d))
        return ((stress**2).sum(axis=0) - lam / (d * lam + 2 * mu) * trace**2) / (2 * mu)
    s11, s22, s12 = stress
    trace = s11 + s22
    return (s11**2 + s22**2 + 2 * s12**2 - lam / (2 * (lam + mu)) * trace**2) / (2 * mu)


def averaging_indicators(solution: DiscreteSolution) -> np.ndarray:
    """||C^{-1/2}(sigma_h - A sigma_h)||_T^2 per element, integrated exactly (degree 2p)."""
    elasticity = solution.elasticity
    lam, mu = elasticity.lame
    order = elasticity.order
    mesh = elasticity.mesh
    scalar = Basis(mesh, family_of(mesh).elements[order](), intorder=2 * order)
    recovered = averaged_stress(solution, scalar)
    at_points = np.array([np.asarray(scalar.interpolate(r)) for r in recovered])
    grad = Basis(mesh, elasticity.basis.elem, quadrature=scalar.quadrature)
    stress = stresses(grad.interpolate(solution.u).grad, (lam, mu))
    return (compliance_energy(stress - at_points, lam, mu) * scalar.dx).sum(axis=1)


@register_estimator("averaging", "Zienkiewicz-Zhu nodal stress averaging in the energy norm "
                                 "plus the geometric and complementarity contact terms of (8); "
                                 "with friction the friction complementarity",
                    families=("tri", "tet", "quad", "hex"), friction=(2, 3))
def estimate(scene, solution: DiscreteSolution) -> Estimate:
    return combine("averaging", averaging_indicators(solution), contact_terms(scene, solution))

"""Discretisation errors of a solution against an exact solution (docs/theory.md, section 6):

* energy-norm error ||u - u_h|| = a(u - u_h, u - u_h)^(1/2);
* contact-pressure error ||lambda - lambda_h||_{0, Gamma_C};
* contact-zone error: the larger distance between computed and true zone end points.

Against an exact solution the integrals run over the mesh of u_h with a rule of order
6 + 2(p - 1) (exact for u_h of order p, accurate for the smooth u); against a reference on
another mesh see
``bench.measure.nonnested``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from skfem import Basis

from bench.measure.contact import contact_zone, zone_error, zone_jaccard
from formulations import DiscreteSolution
from formulations.elasticity import stress_from_gradient, stress_tensor_from_gradient
from formulations.friction.state import traction_size

EXACT_INTORDER = 6  # plus 2 (p - 1) for P_p: the u_h part of the integrand stays exact
PRESSURE_POINTS = 6  # Gauss points per contact facet for ||lambda - lambda_h||


@dataclass(frozen=True)
class Errors:
    energy_error: float
    pressure_error: float
    zone_error: float
    contact_zone_start: float
    contact_zone_end: float
    zone_jaccard: float = float("nan")  # Jaccard's distance to the true zone


def energy_density(grad: np.ndarray, lam: float, mu: float) -> np.ndarray:
    """sigma(e) : eps(e) for the displacement gradient grad[i, j] of e (2D or 3D)."""
    if grad.shape[0] == 3:
        return np.einsum("ij...,ij...->...", stress_tensor_from_gradient(grad, lam, mu), grad)
    s11, s22, s12 = stress_from_gradient(grad, lam, mu)
    return s11 * grad[0, 0] + s22 * grad[1, 1] + s12 * (grad[0, 1] + grad[1, 0])


def pressure_error(solution: DiscreteSolution, true_pressure, trace=None) -> float:
    """||lambda - lambda_h||_{0,Gamma_C} on the facets of ``trace`` (the finer one; default
    u_h's), with ``true_pressure(s)`` a function of the contact coordinate."""
    trace = solution.trace if trace is None else trace
    t, w = trace.rule(2 * PRESSURE_POINTS - 1)
    values = solution.pressure_at(trace.row_coordinates(t)).reshape(trace.size, -1)
    diff = true_pressure(trace.coordinates_at(t)) - values
    return float(np.sqrt(trace.integrate(diff**2, w).sum()))


def shear_error(solution: DiscreteSolution, true_shear) -> float:
    """||sigma_t - sigma_t,h||_{0,Gamma_C} on u_h's contact facets, with ``true_shear(s)`` a
    function of the contact coordinate (in 3D a vector, (3, ...), as sigma_t,h is)."""
    trace = solution.trace
    t, w = trace.rule(2 * PRESSURE_POINTS - 1)  # 2D: PRESSURE_POINTS Gauss points
    diff = true_shear(trace.coordinates_at(t)) - solution.friction.traction(t)
    return float(np.sqrt(trace.integrate(traction_size(diff) ** 2, w).sum()))


def errors_from(energy_error: float, solution: DiscreteSolution, true_pressure,
                true_zone) -> Errors:
    """The pressure and zone errors of ``solution`` beside a measured energy-norm error."""
    zone = contact_zone(solution)
    return Errors(energy_error, pressure_error(solution, true_pressure),
                  zone_error(zone, true_zone), *zone, zone_jaccard(zone, true_zone))


def element_energy_errors(scene, solution: DiscreteSolution) -> np.ndarray:
    """||u - u_h||^2_T per element against ``scene.exact`` (quadrature of order
    EXACT_INTORDER + 2(p - 1))."""
    order = solution.elasticity.order
    basis = Basis(solution.elasticity.mesh, solution.elasticity.basis.elem,
                  intorder=EXACT_INTORDER + 2 * (order - 1))
    grad_h = basis.interpolate(solution.u).grad
    diff = scene.exact.gradient(np.asarray(basis.global_coordinates())) - grad_h
    return (energy_density(diff, *solution.elasticity.lame) * basis.dx).sum(axis=1)


def exact_errors(scene, solution: DiscreteSolution) -> Errors:
    exact = scene.exact
    energy = float(element_energy_errors(scene, solution).sum())
    return errors_from(np.sqrt(max(energy, 0.0)), solution, exact.pressure, exact.contact_zone)

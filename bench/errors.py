"""Errors of a discrete solution against the truth: an exact solution or an overkill reference.

* energy-norm error ||u - u_h|| = a(u - u_h, u - u_h)^(1/2);
* contact-pressure error ||lambda - lambda_h||_{0, Gamma_C};
* contact-zone error: the larger distance between computed and true zone end points.

Against an exact solution the integrals run over the mesh of u_h with a 6th-order rule (exact
for u_h, accurate for the smooth u). Against a reference on another mesh they run over the
(finer) reference mesh with the centroid rule: u_h's gradient is found at each reference
centroid by point location in u_h's mesh. When the reference mesh refines u_h's mesh (uniform or
nested adaptive sequences) this is exact; otherwise a reference element that straddles an edge
of u_h's mesh is integrated with u_h's gradient from the side of its centroid, an error confined
to a layer of reference elements along u_h's edges (tests/bench/test_errors.py measures both).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from matplotlib.tri import Triangulation
from skfem import Basis, ElementTriP1, ElementVector

from formulations import DiscreteSolution
from formulations.contact import gauss_legendre
from formulations.elasticity import stress_from_gradient
from formulations.kkt import ACTIVE_FRACTION

TOO_COARSE = 0.1  # a reference whose own error exceeds 10 % of the measured error is too coarse
EXACT_INTORDER = 6
PRESSURE_POINTS = 6  # Gauss points per contact facet for ||lambda - lambda_h||


@dataclass(frozen=True)
class Errors:
    energy_error: float
    pressure_error: float
    zone_error: float
    contact_zone_start: float
    contact_zone_end: float


def solution_difference(discretisation, solution, judge) -> tuple[float, float]:
    """Two solutions of the same discrete problem compared: relative energy-norm difference of
    u_h and max pressure difference (at 5 points per contact facet) relative to max lambda_h.
    The energy norm is relative to max(||u_judge||, sqrt(E) d) and the pressure to
    max(max lambda_judge, E d / |Gamma_C|), d the QP's gap scale, so that a vanishing solution
    or pressure (nothing touches) is not divided by zero."""
    K = discretisation.elasticity.K
    du = solution.u - judge.u
    t = np.linspace(0.0, 1.0, 5)
    lam, lam_ref = solution.pressure(t), judge.pressure(t)
    qp = discretisation.qp
    scale = max(np.sqrt(judge.u @ K @ judge.u), np.sqrt(qp.objective_scale) * qp.gap_scale,
                1e-300)
    return (float(np.sqrt(du @ K @ du) / scale),
            float(np.abs(lam - lam_ref).max()
                  / max(np.abs(lam_ref).max(), qp.objective_scale * qp.gap_scale
                        / discretisation.trace.length.sum(), 1e-300)))


def energy_density(grad: np.ndarray, lam: float, mu: float) -> np.ndarray:
    """sigma(e) : eps(e) for the displacement gradient grad[i, j] of e."""
    s11, s22, s12 = stress_from_gradient(grad, lam, mu)
    return s11 * grad[0, 0] + s22 * grad[1, 1] + s12 * (grad[0, 1] + grad[1, 0])


def element_gradients(solution: DiscreteSolution) -> np.ndarray:
    """The constant P1 gradient per element, shape (2, 2, n_elements)."""
    return solution.elasticity.basis.interpolate(solution.u).grad[:, :, :, 0]


def contact_zone(solution: DiscreteSolution) -> tuple[float, float]:
    """End points (contact coordinates) of the union of contact facets where lambda_h > 0,
    i.e. above ACTIVE_FRACTION x max lambda_h: an interior-point solution leaves multipliers
    of ~1e-9 relative on every facet, which are not contact."""
    values = solution.pressure(np.array([0.25, 0.5, 0.75]))
    pressed = (values > ACTIVE_FRACTION * values.max(initial=0.0)).any(axis=1)
    if not pressed.any():
        return float("nan"), float("nan")
    s0, s1 = solution.trace.coordinate
    return float(s0[pressed].min()), float(s1[pressed].max())


def _zone_error(zone, true_zone) -> float:
    return float(max(abs(zone[0] - true_zone[0]), abs(zone[1] - true_zone[1])))


def pressure_error(solution: DiscreteSolution, true_pressure, trace=None) -> float:
    """||lambda - lambda_h||_{0,Gamma_C} on the facets of ``trace`` (the finer one; default
    u_h's), with ``true_pressure(s)`` a function of the contact coordinate."""
    trace = solution.trace if trace is None else trace
    t, w = gauss_legendre(PRESSURE_POINTS)
    s = trace.coordinate[0][:, None] + np.diff(trace.coordinate, axis=0).T * t[None, :]
    diff = true_pressure(s) - solution.pressure_at(s.ravel()).reshape(s.shape)
    return float(np.sqrt(trace.integrate(diff**2, w).sum()))


def exact_errors(scene, solution: DiscreteSolution) -> Errors:
    exact = scene.exact
    mesh = solution.elasticity.mesh
    basis = Basis(mesh, ElementVector(ElementTriP1()), intorder=EXACT_INTORDER)
    grad_h = basis.interpolate(solution.u).grad
    diff = exact.gradient(np.asarray(basis.global_coordinates())) - grad_h
    density = energy_density(diff, *solution.elasticity.lame)
    energy = float((density * basis.dx).sum())
    zone = contact_zone(solution)
    return Errors(np.sqrt(max(energy, 0.0)), pressure_error(solution, exact.pressure),
                  _zone_error(zone, exact.contact_zone), *zone)


def locate(mesh, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Index of the element of ``mesh`` containing each point (matplotlib's trapezoid-map
    finder: O(log n) per point, unlike a brute-force search)."""
    triangulation = Triangulation(mesh.p[0], mesh.p[1], mesh.t.T)
    element = triangulation.get_trifinder()(x, y)
    if (element < 0).any():
        bad = np.flatnonzero(element < 0)[0]
        raise ValueError(f"point ({x[bad]}, {y[bad]}) lies outside the mesh")
    return element


@dataclass(frozen=True, eq=False)
class P1Field:
    """A P1 displacement on its own mesh, reduced to what error integration needs: the constant
    gradient, centroid and area of every element (computed once, reused for every u_h)."""

    gradient: np.ndarray  # (2, 2, n_elements)
    centroid: np.ndarray  # (2, n_elements)
    area: np.ndarray

    @classmethod
    def from_nodal(cls, mesh, u_nodal: np.ndarray) -> P1Field:
        p = mesh.p[:, mesh.t]  # (2, 3, nT)
        a, b = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
        det = a[0] * b[1] - a[1] * b[0]
        # gradients of the barycentric coordinates l1, l2 (l0 = 1 - l1 - l2)
        g1, g2 = np.array([b[1], -b[0]]) / det, np.array([-a[1], a[0]]) / det
        u = u_nodal[:, mesh.t]  # (2 components, 3 vertices, nT)
        du1, du2 = u[:, 1] - u[:, 0], u[:, 2] - u[:, 0]
        gradient = du1[:, None, :] * g1[None] + du2[:, None, :] * g2[None]
        return cls(gradient, p.mean(axis=1), 0.5 * np.abs(det))


def energy_error_on(field: P1Field, lame, solution: DiscreteSolution) -> float:
    """||u - u_h|| for a P1 ``field`` on another (finer) mesh, integrated over that mesh with
    u_h's gradient located at each element's centroid (module docstring). Where the fine mesh
    refines u_h's mesh the centroid rule is exact: both gradients are constant per element."""
    element = locate(solution.elasticity.mesh, field.centroid[0], field.centroid[1])
    grad_h = element_gradients(solution)[:, :, element]
    energy = float((energy_density(field.gradient - grad_h, *lame) * field.area).sum())
    return float(np.sqrt(max(energy, 0.0)))

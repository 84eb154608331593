"""The energy-norm error of u_h (any order) against a P1 field on another (finer, possibly
non-nested) mesh.

The integral runs over the reference mesh with the centroid rule for P1 u_h (a rule of degree
2(p - 1) for P_p): u_h's gradient is found at each point by point location in u_h's mesh.
When the reference mesh refines u_h's
mesh (uniform or nested adaptive sequences) this is exact; otherwise a reference element that
straddles an edge of u_h's mesh is integrated with u_h's gradient from the side of its centroid,
an error confined to a layer of reference elements along u_h's edges
(tests/bench/measure/test_discretisation_error.py measures both).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from matplotlib.tri import Triangulation
from skfem.quadrature import get_quadrature
from skfem.refdom import RefTri

from bench.measure.discretisation_error import element_gradients, energy_density
from formulations import DiscreteSolution
from formulations.evaluation import gradients_at


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
    corners: np.ndarray  # (2, 3, n_elements): the vertices of every element

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
        return cls(gradient, p.mean(axis=1), 0.5 * np.abs(det), p)


def energy_error_on(field: P1Field, lame, solution: DiscreteSolution) -> float:
    """||u - u_h|| for a P1 ``field`` on another (finer) mesh, integrated over that mesh with
    u_h's gradient located at each quadrature point (module docstring): the centroid for P1
    u_h, a rule of degree 2(p - 1) for P_p. Where the fine mesh refines u_h's mesh the rule is
    exact: the integrand is a polynomial of that degree on every fine element."""
    order = solution.elasticity.order
    if order == 1:
        element = locate(solution.elasticity.mesh, field.centroid[0], field.centroid[1])
        grad_h = element_gradients(solution)[:, :, element]
        energy = float((energy_density(field.gradient - grad_h, *lame) * field.area).sum())
        return float(np.sqrt(max(energy, 0.0)))
    X, W = get_quadrature(RefTri, 2 * (order - 1))  # sum W = 1/2, the reference area
    c = field.corners
    x = (c[:, 0, :, None] + (c[:, 1] - c[:, 0])[:, :, None] * X[0]
         + (c[:, 2] - c[:, 0])[:, :, None] * X[1]).reshape(2, -1)  # element-major
    mesh = solution.elasticity.mesh
    grad_h = gradients_at(solution.elasticity.basis, solution.u, x, locate(mesh, *x))
    difference = np.repeat(field.gradient, W.size, axis=2) - grad_h
    weight = np.repeat(field.area, W.size) * np.tile(2.0 * W, field.area.size)
    energy = float((energy_density(difference, *lame) * weight).sum())
    return float(np.sqrt(max(energy, 0.0)))

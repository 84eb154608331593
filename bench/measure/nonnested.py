"""The energy-norm error of u_h against a P1 field on another (finer, possibly non-nested) mesh.

The integral runs over the reference mesh with the centroid rule: u_h's gradient is found at
each reference centroid by point location in u_h's mesh. When the reference mesh refines u_h's
mesh (uniform or nested adaptive sequences) this is exact; otherwise a reference element that
straddles an edge of u_h's mesh is integrated with u_h's gradient from the side of its centroid,
an error confined to a layer of reference elements along u_h's edges
(tests/bench/measure/test_discretisation_error.py measures both).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from matplotlib.tri import Triangulation

from bench.measure.discretisation_error import element_gradients, energy_density
from formulations import DiscreteSolution


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

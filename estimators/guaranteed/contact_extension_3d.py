"""The extension d of the penetration w = (g - u_hn)_- on tetrahedra (docs/theory.md, section
14.5; the segments' ``estimators.guaranteed.contact_extension`` in 3D). Any d in H^1_D with d . n <=
w on Gamma_C gives a bound; two are built, and the estimate keeps the one with the smaller bound:

* ``floor_extension``: d = sum_a c_a psi_a nu_a, c_a (nu_a . n_e) <= min w over every contact
  triangle e at a, so d . n, a convex combination of its vertex values on a triangle, stays
  below min w there; c_a = 0 on Gamma_D.
* ``fitted_extension``: the vertex values follow w along the edges (c_a (nu_a . n_e) <= min w
  over the two edges of e at a, for every triangle e at a: on an edge d . n is then below w),
  and on each triangle a face bubble b_e 27 l_0 l_1 l_2 n_e (the cubic bubble of the
  triangle's tetrahedron, zero on its other faces, so d stays conforming) takes the largest
  coefficient with d . n <= w at the samples inside the triangle: the gap between a curved
  obstacle and the piecewise linear u_hn, deepest inside the triangles, that the floor pays
  for on every triangle of a contact zone.

w is sampled on a lattice of SAMPLE_DIVISIONS per edge (as on segments: data that is not
piecewise polynomial is the stated exception, docs/theory.md 13.5).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from skfem.quadrature import get_quadrature
from skfem.refdom import RefTet

from estimators.guaranteed.contact_extension import discrete_gap, vertex_field
from formulations.cells.p1_stiffness import barycentric_gradients
from formulations.elasticity import stress_tensor_from_gradient

SAMPLE_DIVISIONS = 8   # d . n <= w is imposed on this lattice per contact triangle
ENERGY_ORDER = 5       # the bubble's energy density is quartic; this rule's weights are positive


def lattice(divisions: int) -> np.ndarray:
    """The points (i, j) / m, i + j <= m, of the reference triangle, (2, n)."""
    return np.array([(i / divisions, j / divisions) for i in range(divisions + 1)
                     for j in range(divisions + 1 - i)]).T


def corner_weights(t: np.ndarray) -> np.ndarray:
    """The P1 basis (3, nq) of the reference triangle at local coordinates t (2, nq)."""
    return np.array([1.0 - t[0] - t[1], t[0], t[1]])


@dataclass(frozen=True, eq=False)
class SurfaceExtension:
    """d = sum_a nodal[:, a] psi_a + sum_e bubble[e] 27 l_0 l_1 l_2 n_e (module docstring)."""

    nodal: np.ndarray    # (3, n_vertices)
    bubble: np.ndarray   # (n_f,) along the outer normal of each contact triangle

    def normal_part(self, surface, t: np.ndarray) -> np.ndarray:
        """d . n (n_f, nq) at local coordinates t of the contact triangles."""
        corner = np.array([np.einsum("if,if->f", self.nodal[:, v], surface.normal)
                           for v in surface.vertices])                # (3, n_f)
        weights = corner_weights(t)
        return corner.T @ weights + self.bubble[:, None] * 27 * weights.prod(axis=0)

    def tangential_part(self, surface, t: np.ndarray) -> np.ndarray:
        """d - (d . n) n (3, n_f, nq) at local coordinates t (the bubbles are normal)."""
        d = np.einsum("icf,cq->ifq", self.nodal[:, surface.vertices], corner_weights(t))
        n = surface.normal[:, :, None]
        return d - (d * n).sum(axis=0) * n

    def energy(self, mesh, lame: tuple[float, float], surface) -> np.ndarray:
        """a(d, d) per element (the bubbles' tetrahedra on a rule of ENERGY_ORDER)."""
        gradients, volume = barycentric_gradients(mesh)                   # (4, 3, n_el)
        grad = np.einsum("iae,ake->ike", self.nodal[:, mesh.t], gradients)
        energy = volume * np.einsum("ije,ije->e", stress_tensor_from_gradient(grad, *lame), grad)
        if not np.any(self.bubble):
            return energy
        holders, slot = np.unique(surface.element, return_inverse=True)
        X, W = get_quadrature(RefTet, ENERGY_ORDER)
        lam = np.vstack([1 - X.sum(axis=0), X])                        # (4, nq)
        local = np.repeat(grad[:, :, holders, None], W.size, axis=3)   # (3, 3, m, nq)
        corners = [(mesh.t[:, surface.element] == v).argmax(axis=0) for v in surface.vertices]
        g = gradients[:, :, surface.element]                           # (4, 3, n_f)
        bubble_grad = 27 * sum(lam[corners[(i + 1) % 3]] * lam[corners[(i + 2) % 3]]
                               * g[corners[i], :, np.arange(surface.size)].T[:, :, None]
                               for i in range(3))                      # (3, n_f, nq)
        part = (self.bubble * surface.normal)[:, None, :, None] * bubble_grad[None]
        np.add.at(local, (slice(None), slice(None), slot), part)
        density = np.einsum("ijmq,ijmq->mq", stress_tensor_from_gradient(local, *lame), local)
        energy[holders] = 6 * volume[holders] * (density @ W)
        return energy


def floor_extension(scene, solution, clamped: np.ndarray) -> SurfaceExtension:
    """The floor of the module docstring."""
    surface = solution.trace
    w = np.minimum(discrete_gap(scene, solution, lattice(SAMPLE_DIVISIONS)), 0.0)
    floor = np.broadcast_to(w.min(axis=1), (3, surface.size))
    return SurfaceExtension(vertex_field(surface, floor, clamped), np.zeros(surface.size))


def fitted_extension(scene, solution, clamped: np.ndarray) -> SurfaceExtension:
    """The fit of the module docstring."""
    surface = solution.trace
    t = lattice(SAMPLE_DIVISIONS)
    w = np.minimum(discrete_gap(scene, solution, t), 0.0)
    weights = corner_weights(t)
    on_edge = np.isclose(weights, 0.0)                       # on the edge opposite corner i
    levels = np.array([w[:, on_edge[(i + 1) % 3] | on_edge[(i + 2) % 3]].min(axis=1)
                       for i in range(3)])                    # min of w on corner i's edges
    linear = SurfaceExtension(vertex_field(surface, levels, clamped), np.zeros(surface.size))
    inside = weights.prod(axis=0) > 1e-12
    room = (w - linear.normal_part(surface, t))[:, inside] / (27 * weights.prod(axis=0)[inside])
    return SurfaceExtension(linear.nodal, room.min(axis=1))


EXTENSIONS_3D = (floor_extension, fitted_extension)

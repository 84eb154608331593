"""The extension d of the penetration w = (g - u_hn)_- in the guaranteed bound (docs/theory.md,
section 13.3): any d in H^1_D with d . n <= w on Gamma_C gives a bound, and its energy D = ||d||
and the slack g - u_hn - d . n that the complementarity term B integrates both grow with the
room d . n leaves below w. Two one-layer fields are built, and the estimate keeps whichever
gives the smaller bound:

* ``vertex_extension``: d = sum_a c_a psi_a nu_a with c_a below min w over the facets at a;
  d . n is a constant-level floor under w on each facet;
* ``fitted_extension``: the vertex values follow w at the vertices and a quadratic facet
  bubble b_e 4 t (1 - t) n_e (the P2 edge function of the facet's element, zero on its other
  two edges) follows w between them, so d . n meets w at both ends of a facet and under the
  deepest point of its bump: the gap between curved obstacle and P1 chord that the floor
  pays for on every facet of a contact zone.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from estimators.averaging import element_areas
from formulations.cells.p1_stiffness import barycentric_gradients
from formulations.elasticity import stress_from_gradient

SAMPLES = 33  # points per contact facet at which d . n <= w is imposed (ends included)
# Three edge midpoints, weights 1/3: exact for the quadratic energy density of a P2 field.
MIDPOINTS = np.array([[0.5, 0.5, 0.0], [0.0, 0.5, 0.5], [0.5, 0.0, 0.5]])


@dataclass(frozen=True, eq=False)
class Extension:
    """d = sum_a nodal[:, a] psi_a + sum_e bubble[e] 4 lambda_start lambda_end n_e."""

    nodal: np.ndarray   # (2, n_vertices)
    bubble: np.ndarray  # (n_f,) along the outer normal of each contact facet

    def along(self, trace, direction: np.ndarray, t: np.ndarray) -> np.ndarray:
        """d . direction at local points t of every contact facet (direction (2, n_f)),
        (n_f, len(t))."""
        start, end = (np.einsum("if,if->f", self.nodal[:, v], direction)[:, None]
                      for v in trace.vertices)
        bubble = self.bubble * np.einsum("if,if->f", trace.normal, direction)
        return start * (1 - t) + end * t + bubble[:, None] * (4 * t * (1 - t))

    def energy(self, trace, lame: tuple[float, float]) -> np.ndarray:
        """a(d, d) per element."""
        mesh = trace.mesh
        gradients = barycentric_gradients(mesh)[0]                       # (3, 2, n_el)
        grad = np.einsum("iae,ake->ike", self.nodal[:, mesh.t], gradients)  # du_i/dx_k
        energy = element_areas(mesh) * _density(grad[..., None], lame)[:, 0]
        holders, slot = np.unique(trace.element, return_inverse=True)
        local = grad[:, :, holders, None].repeat(len(MIDPOINTS), axis=3)   # (2, 2, m, 3)
        ends = [(mesh.t[:, trace.element] == v).argmax(axis=0) for v in trace.vertices]
        g = [gradients[k, :, trace.element].T for k in ends]             # (2, n_f) each
        lam = [MIDPOINTS[:, k].T for k in ends]                           # (n_f, 3) each
        grad_bubble = 4 * (lam[1][None] * g[0][:, :, None] + lam[0][None] * g[1][:, :, None])
        contribution = (self.bubble * trace.normal)[:, None, :, None] * grad_bubble[None]
        np.add.at(local, (slice(None), slice(None), slot), contribution)
        energy[holders] = element_areas(mesh)[holders] * _density(local, lame).mean(axis=1)
        return energy


def _density(grad: np.ndarray, lame: tuple[float, float]) -> np.ndarray:
    """sigma : eps for gradients grad[i, j] = d d_i / d x_j, (2, 2, ...)."""
    s11, s22, s12 = stress_from_gradient(grad, *lame)
    return s11 * grad[0, 0] + s22 * grad[1, 1] + s12 * (grad[0, 1] + grad[1, 0])


def discrete_gap(scene, solution, t: np.ndarray) -> np.ndarray:
    """g - u_hn at local points t of every contact facet, (n_f, len(t))."""
    return scene.gap(solution.trace.points(t)) - solution.normal_displacement(t)


def vertex_normals(trace) -> np.ndarray:
    """Measure-weighted mean outer normals at the contact vertices, unit (d, n_vertices), on
    segments (2D) or triangles (3D)."""
    d, n_v = trace.normal.shape[0], trace.mesh.p.shape[1]
    nu = np.zeros((d, n_v))
    for v in trace.vertices:
        for i in range(d):
            nu[i] += np.bincount(v, trace.normal[i] * trace.measure, minlength=n_v)
    norm = np.linalg.norm(nu, axis=0)
    return nu / np.where(norm > 0, norm, 1.0)


def vertex_field(trace, levels, clamped: np.ndarray) -> np.ndarray:
    """c_a nu_a with c_a the largest value whose normal component on every facet at a is at
    most that facet's level there (``levels``: (n_f,) at each of the facet's vertices, in
    ``trace.vertices`` order); c_a = 0 on Gamma_D."""
    nu = vertex_normals(trace)
    c = np.zeros(trace.mesh.p.shape[1])
    for v, level in zip(trace.vertices, levels, strict=True):
        np.minimum.at(c, v, level / np.einsum("if,if->f", nu[:, v], trace.normal))
    c[clamped] = 0.0  # d must vanish on Gamma_D
    return c * nu


def vertex_extension(scene, solution, clamped: np.ndarray) -> Extension:
    """The floor: c_a <= (min_e w) / (nu_a . n_e) over the facets e at a, so that d . n, a
    convex combination of its vertex values on a facet, stays below min_e w."""
    trace = solution.trace
    w = np.minimum(discrete_gap(scene, solution, np.linspace(0.0, 1.0, SAMPLES)), 0.0)
    floor = w.min(axis=1)
    return Extension(vertex_field(trace, [floor, floor], clamped), np.zeros(trace.size))


def fitted_extension(scene, solution, clamped: np.ndarray) -> Extension:
    """The fit: vertex values at w's own vertex values, then on each facet the largest bubble
    coefficient b_e with d . n <= w at the samples inside it."""
    trace = solution.trace
    s = np.linspace(0.0, 1.0, SAMPLES)
    w = np.minimum(discrete_gap(scene, solution, s), 0.0)
    linear = Extension(vertex_field(trace, [w[:, 0], w[:, -1]], clamped), np.zeros(trace.size))
    inner = s[1:-1]
    room = (w - linear.along(trace, trace.normal, s))[:, 1:-1] / (4 * inner * (1 - inner))
    return Extension(linear.nodal, room.min(axis=1))


EXTENSIONS = (vertex_extension, fitted_extension)

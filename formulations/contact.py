"""The contact boundary Gamma_C of one mesh: facets in order, normals, quadrature.

Facets are sorted by the scene's ``contact_coordinate`` and oriented so that ``start`` has the
smaller coordinate. Normals are OUTER unit normals (docs/theory.md, section 1).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from skfem import MeshTri

from formulations.contact_surface import contact_surface, triangle_lagrange
from scenes import Scene


def gauss_legendre(n: int) -> tuple[np.ndarray, np.ndarray]:
    """n-point Gauss-Legendre rule on [0, 1]: points t and weights w (sum w = 1)."""
    x, w = np.polynomial.legendre.leggauss(n)
    return 0.5 * (x + 1.0), 0.5 * w


@dataclass(frozen=True, eq=False)
class ContactTrace:
    """Contact facets of ``mesh`` ordered along Gamma_C.

    ``vertices`` (2, n) are the mesh vertices at the start and end of each facet, ``normal``
    (2, n) the outer unit normal, ``length`` (n,) the facet lengths, ``coordinate`` (2, n) the
    scene coordinate of start and end, ``element`` (n,) the element each facet belongs to.
    """

    mesh: MeshTri
    facets: np.ndarray
    vertices: np.ndarray
    normal: np.ndarray
    length: np.ndarray
    coordinate: np.ndarray
    element: np.ndarray
    dim = 2  # of the body (``formulations.contact_surface.ContactSurface`` is the 3D one)

    @property
    def size(self) -> int:
        return int(self.facets.size)

    @property
    def measure(self) -> np.ndarray:
        """The facets' measures (lengths): what ``ContactSurface.measure`` is in 3D."""
        return self.length

    @property
    def diameter(self) -> np.ndarray:
        return self.length

    @staticmethod
    def rule(degree: int) -> tuple[np.ndarray, np.ndarray]:
        """The Gauss-Legendre rule exact to ``degree`` (``(degree + 2) // 2`` points)."""
        return gauss_legendre((int(degree) + 2) // 2)

    def points(self, t: np.ndarray) -> np.ndarray:
        """Points at local coordinates t in [0, 1] on each facet; shape (2, n, len(t))."""
        a = self.mesh.p[:, self.vertices[0]][:, :, None]
        b = self.mesh.p[:, self.vertices[1]][:, :, None]
        return a + (b - a) * t[None, None, :]

    def coordinates_at(self, t: np.ndarray) -> np.ndarray:
        """Contact coordinates at local coordinates t in [0, 1] on each facet; shape
        (n, len(t))."""
        return facet_coordinates(self.coordinate, t)

    @property
    def tangent(self) -> np.ndarray:
        """Unit tangents (2, n), pointing from ``start`` to ``end``."""
        a, b = self.mesh.p[:, self.vertices[0]], self.mesh.p[:, self.vertices[1]]
        return (b - a) / self.length

    def row_coordinates(self, t: np.ndarray) -> np.ndarray:
        """Contact coordinates of the points t of every facet, one per row (facet f, point q
        -> row f * len(t) + q): what a formulation's ``row_coordinate`` holds."""
        return self.coordinates_at(t).ravel()

    @staticmethod
    def interpolation(points: np.ndarray, t: np.ndarray) -> np.ndarray:
        """The Lagrange polynomials on ``points`` (k,) at t; shape (k, len(t))."""
        return lagrange_basis(points, t)

    def integrate(self, values: np.ndarray, w: np.ndarray) -> np.ndarray:
        """Per-facet integrals of ``values`` (n, nq) given at points with weights w on [0, 1]."""
        return (values * w[None, :]).sum(axis=1) * self.length


@dataclass(frozen=True, eq=False)
class TraceNodes:
    """The Lagrange nodes of the displacement on Gamma_C: the facet end vertices, then the
    p - 1 nodes inside every facet. ``facet_rows`` (n_facets, p + 1) gives, per facet, the row
    of each node in order of t = k / p."""

    points: np.ndarray        # (2, m)
    normal: np.ndarray        # (2, m) unit, length-weighted mean at a vertex
    weight: np.ndarray        # (m,) int_{Gamma_C} phi_i ds (lumped boundary mass)
    facet_rows: np.ndarray    # (n_facets, p + 1); 3D: (n_facets, 3 or 6), ElementTriP2's order
    vertices: np.ndarray      # mesh vertex of each of the first rows
    edges: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))  # 3D P2: then
    # the mesh edge of each midpoint row


def lagrange_nodes(order: int) -> np.ndarray:
    """The equispaced nodes k / p (k = 0..p) on [0, 1] of the trace of a P_p Lagrange element
    on one facet."""
    return np.linspace(0.0, 1.0, order + 1)


def lagrange_basis(nodes: np.ndarray, t: np.ndarray) -> np.ndarray:
    """The 1D Lagrange polynomials on ``nodes`` at t; shape (len(nodes), len(t))."""
    t = np.asarray(t, dtype=float)
    out = np.ones((nodes.size, t.size))
    for k in range(nodes.size):
        for j in range(nodes.size):
            if j != k:
                out[k] *= (t - nodes[j]) / (nodes[k] - nodes[j])
    return out


def lagrange_basis_1d(order: int, t: np.ndarray) -> np.ndarray:
    """The 1D Lagrange polynomials of degree p on the nodes ``lagrange_nodes(p)`` at t;
    shape (p + 1, len(t))."""
    return lagrange_basis(lagrange_nodes(order), t)


def facet_coordinates(coordinate: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Contact coordinates at local coordinates t in [0, 1] of facets whose end points are
    ``coordinate`` (2, n); shape (n, len(t)) (affine along a facet of a straight Gamma_C)."""
    s0, s1 = coordinate
    return s0[:, None] + (s1 - s0)[:, None] * np.asarray(t)[None, :]


def outer_normals(mesh: MeshTri, v0: np.ndarray, v1: np.ndarray, element: np.ndarray):
    """Lengths and outer unit normals of boundary facets (v0, v1) of the given elements."""
    a, b = mesh.p[:, v0], mesh.p[:, v1]
    length = np.linalg.norm(b - a, axis=0)
    normal = np.array([b[1] - a[1], a[0] - b[0]]) / length
    centroid = mesh.p[:, mesh.t[:, element]].mean(axis=1)
    inward = np.einsum("in,in->n", normal, centroid - 0.5 * (a + b)) > 0
    normal[:, inward] *= -1.0
    return length, normal


def contact_trace(scene: Scene, mesh: MeshTri):
    """Gamma_C of ``mesh``: a ``ContactTrace`` (2D) or a ``ContactSurface`` (3D)."""
    if mesh.dim() == 3:
        return contact_surface(scene, mesh)
    facets = scene.contact_facets(mesh)
    v0, v1 = mesh.facets[0, facets], mesh.facets[1, facets]
    s0 = scene.contact_coordinate(mesh.p[:, v0])
    s1 = scene.contact_coordinate(mesh.p[:, v1])
    swap = s1 < s0
    v0, v1 = np.where(swap, v1, v0), np.where(swap, v0, v1)
    s0, s1 = np.minimum(s0, s1), np.maximum(s0, s1)
    order = np.argsort(s0, kind="stable")
    facets, v0, v1, s0, s1 = facets[order], v0[order], v1[order], s0[order], s1[order]

    element = mesh.f2t[0, facets]
    length, normal = outer_normals(mesh, v0, v1, element)
    return ContactTrace(mesh=mesh, facets=facets, vertices=np.array([v0, v1]), normal=normal,
                        length=length, coordinate=np.array([s0, s1]), element=element)


def gap_interpolant(scene: Scene, trace, order: int):
    """g_h: the P_order Lagrange interpolant of g on each contact facet, as a function of the
    local coordinates t (n_facets, len(t)). The penalty and Nitsche's method use it
    (docs/theory.md, sections 3 and 12) so that g - g_h, multiplied by 1/eps or gamma, cannot
    spoil lambda_h between quadrature points."""
    if trace.dim == 3:
        nodes, basis = triangle_lagrange(order)
        values = np.asarray(scene.gap(trace.points(nodes)), dtype=float)  # (n, k)
        return lambda t: values @ basis(np.asarray(t, dtype=float))
    nodes = lagrange_nodes(order)
    values = np.asarray(scene.gap(trace.points(nodes).reshape(2, -1)),
                        dtype=float).reshape(trace.size, nodes.size)
    return lambda t: values @ lagrange_basis_1d(order, np.asarray(t, dtype=float))

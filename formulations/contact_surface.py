"""The contact boundary Gamma_C of a tetrahedral mesh: triangular facets, their outer normals,
quadrature on them and the location of contact coordinates (docs/theory.md, section 14).

It answers the same questions as the 2D ``ContactTrace`` (``formulations.contact``), with local
coordinates t of shape (2, nq) in the reference triangle (x = a + t_0 (b - a) + t_1 (c - a))
instead of (nq,) along a segment, so that a formulation written against ``points``, ``rule``,
``integrate``, ``measure`` and ``diameter`` runs in both dimensions.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree
from skfem import ElementTriP1, ElementTriP2, ElementTriP3, Mesh
from skfem.quadrature import get_quadrature_tri

from scenes.base import simplex_measures, simplex_points

# the reference triangle's vertices as local coordinates (2, 3)
TRIANGLE_VERTICES = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
# candidate facets per located point: the nearest centroids (in contact coordinates) tried
CANDIDATES = 8


# scikit-fem's triangle rules of these degrees have a negative weight: the next one is taken (a
# penalty weight D_q must be positive)
NEGATIVE_WEIGHT_DEGREES = (3, 7)


def triangle_rule(degree: int) -> tuple[np.ndarray, np.ndarray]:
    """A rule exact to ``degree`` with positive weights on the reference triangle: points t
    (2, nq) and weights w (nq,) with sum w = 1 (scikit-fem's rules, whose weights sum to the
    area 1/2)."""
    degree = max(int(degree), 1)
    t, w = get_quadrature_tri(degree + (degree in NEGATIVE_WEIGHT_DEGREES))
    return t, 2.0 * w


def triangle_lagrange(order: int):
    """The Lagrange nodes (2, k) of P_order on the reference triangle (scikit-fem's
    ``ElementTriP*`` DOF order: vertices, edges, interior) and ``basis(t)`` (k, nq), the
    Lagrange polynomials at local coordinates t (2, nq)."""
    element = {1: ElementTriP1, 2: ElementTriP2, 3: ElementTriP3}[int(order)]()
    nodes = np.asarray(element.doflocs, dtype=float).T

    def basis(t: np.ndarray) -> np.ndarray:
        return np.array([element.lbasis(np.asarray(t, dtype=float), k)[0]
                         for k in range(nodes.shape[1])])

    return nodes, basis


def barycentric(corners: np.ndarray, s: np.ndarray) -> np.ndarray:
    """Local coordinates (2, m) of points s (2, m) in 2D triangles with corners (2, 3, m)."""
    a, b, c = corners[:, 0], corners[:, 1], corners[:, 2]
    e1, e2, r = b - a, c - a, s - a
    det = e1[0] * e2[1] - e1[1] * e2[0]
    return np.array([(r[0] * e2[1] - r[1] * e2[0]) / det, (e1[0] * r[1] - e1[1] * r[0]) / det])


@dataclass(frozen=True, eq=False)
class ContactSurface:
    """Contact facets of a tetrahedral ``mesh``. ``vertices`` (3, n) are each facet's corners,
    ``normal`` (3, n) the outer unit normals, ``measure`` (n,) the areas, ``diameter`` (n,) the
    longest edges, ``coordinate`` (2, 3, n) the scene's contact coordinates of the corners and
    ``element`` (n,) the tetrahedron each facet belongs to."""

    mesh: Mesh
    facets: np.ndarray
    vertices: np.ndarray
    normal: np.ndarray
    measure: np.ndarray
    diameter: np.ndarray
    coordinate: np.ndarray
    element: np.ndarray
    dim: int = 3

    @property
    def size(self) -> int:
        return int(self.facets.size)

    def points(self, t: np.ndarray) -> np.ndarray:
        """Points at local coordinates t (2, nq) on each facet; shape (3, n, nq)."""
        return simplex_points(self.mesh.p[:, self.vertices], t)

    def coordinates_at(self, t: np.ndarray) -> np.ndarray:
        """Contact coordinates at local coordinates t (2, nq); shape (2, n, nq) (affine on a
        facet of a plane Gamma_C)."""
        return simplex_points(self.coordinate, t)

    def row_coordinates(self, t: np.ndarray) -> np.ndarray:
        """Contact coordinates (2, n * nq) of the points t of every facet, one column per row
        (facet f, point q -> f * nq + q)."""
        return self.coordinates_at(t).reshape(2, -1)

    @staticmethod
    def rule(degree: int) -> tuple[np.ndarray, np.ndarray]:
        """Quadrature exact to ``degree`` on every facet (``triangle_rule``)."""
        return triangle_rule(degree)

    @staticmethod
    def interpolation(points: np.ndarray, t: np.ndarray) -> np.ndarray:
        """The polynomials of the least total degree that interpolate at ``points`` (2, k)
        (k = 3: linear, 6: quadratic), at local coordinates t (2, nq); shape (k, nq)."""
        degree = {3: 1, 6: 2}[points.shape[1]]
        powers = [(i, j) for i in range(degree + 1) for j in range(degree + 1 - i)]

        def monomials(x):
            return np.array([x[0] ** i * x[1] ** j for i, j in powers])

        return np.linalg.solve(monomials(points), monomials(np.asarray(t, dtype=float)))

    def integrate(self, values: np.ndarray, w: np.ndarray) -> np.ndarray:
        """Per-facet integrals of ``values`` (n, nq) given at points with weights w."""
        return (values * w[None, :]).sum(axis=1) * self.measure

    def locate(self, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The facet holding each contact coordinate s (2, m) and the local coordinates there
        (2, m); a point just outside Gamma_C (round-off) goes to the nearest facet's closure."""
        s = np.asarray(s, dtype=float).reshape(2, -1)
        centroids = self.coordinate.mean(axis=1)
        k = min(CANDIDATES, self.size)
        _, near = cKDTree(centroids.T).query(s.T, k=k)
        near = near.reshape(s.shape[1], k).T  # (k, m)
        local = np.array([barycentric(self.coordinate[:, :, f], s) for f in near])  # (k, 2, m)
        inside = np.minimum(np.minimum(local[:, 0], local[:, 1]), 1 - local[:, 0] - local[:, 1])
        best = np.argmax(inside, axis=0)
        columns = np.arange(s.shape[1])
        t = np.clip(local[best, :, columns].T, 0.0, 1.0)
        over = t.sum(axis=0) > 1.0
        t[:, over] /= t[:, over].sum(axis=0)
        return near[best, columns], t


def outer_triangle_normals(mesh: Mesh, corners: np.ndarray, element: np.ndarray) -> np.ndarray:
    """Outer unit normals (3, n) of boundary triangles with corner points (3, 3, n)."""
    normal = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0], axis=0)
    normal /= np.linalg.norm(normal, axis=0)
    centroid = mesh.p[:, mesh.t[:, element]].mean(axis=1)
    inward = np.einsum("in,in->n", normal, centroid - corners.mean(axis=1)) > 0
    normal[:, inward] *= -1.0
    return normal


def contact_surface(scene, mesh: Mesh) -> ContactSurface:
    """The contact facets of a tetrahedral mesh (in the mesh's facet order)."""
    facets = scene.contact_facets(mesh)
    vertices = mesh.facets[:, facets]
    corners = mesh.p[:, vertices]  # (3, 3, n)
    element = mesh.f2t[0, facets]
    edges = [np.linalg.norm(corners[:, i] - corners[:, (i + 1) % 3], axis=0) for i in range(3)]
    coordinate = np.asarray(scene.contact_coordinate(corners), dtype=float)
    return ContactSurface(mesh=mesh, facets=facets, vertices=vertices,
                          normal=outer_triangle_normals(mesh, corners, element),
                          measure=simplex_measures(corners), diameter=np.max(edges, axis=0),
                          coordinate=coordinate, element=element)

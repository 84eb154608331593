"""Triangles: the contact boundary of a tetrahedral mesh (``formulations.contact.boundary``):
triangular facets, their outer normals, quadrature on them, the location of contact
coordinates, and nodal contact on their P1 and P2 nodes (``formulations.contact.surface_nodes``)
(docs/theory.md, section 14).

It answers the same questions as the 2D ``ContactTrace`` (``formulations.contact.edges``), with
local coordinates t of shape (2, nq) in the reference triangle (x = a + t_0 (b - a) + t_1 (c - a))
instead of (nq,) along a segment.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree
from skfem import Mesh

from formulations.contact.boundary import register_boundary
from formulations.contact.reference_facets import (
    P2_CHILDREN,
    TRIANGLE_SAMPLES,
    barycentric,
    triangle_lagrange,
    triangle_rule,
)
from formulations.contact.surfaces import SurfaceBoundary, contact_faces, outward
from scenes.base import simplex_measures, simplex_points

# candidate facets per located point: the nearest centroids (in contact coordinates) tried
CANDIDATES = 8


@dataclass(frozen=True, eq=False)
class ContactSurface(SurfaceBoundary):
    """Contact facets of a tetrahedral ``mesh``. ``vertices`` (3, n) are each facet's corners,
    ``normal`` (3, n) the outer unit normals, ``measure`` (n,) the areas, ``diameter`` (n,) the
    longest edges, ``coordinate`` (2, 3, n) the scene's contact coordinates of the corners and
    ``element`` (n,) the tetrahedron each facet belongs to."""

    name = "triangles"

    @classmethod
    def of(cls, scene, mesh) -> ContactSurface:
        """The contact facets of a tetrahedral mesh (in the mesh's facet order)."""
        facets, vertices, corners, element, coordinate = contact_faces(scene, mesh)
        edges = [np.linalg.norm(corners[:, i] - corners[:, (i + 1) % 3], axis=0)
                 for i in range(3)]
        return cls(mesh=mesh, facets=facets, vertices=vertices,
                   normal=outer_triangle_normals(mesh, corners, element),
                   measure=simplex_measures(corners), diameter=np.max(edges, axis=0),
                   coordinate=coordinate, element=element)

    def points(self, t: np.ndarray) -> np.ndarray:
        """Points at local coordinates t (2, nq) on each facet; shape (3, n, nq)."""
        return simplex_points(self.mesh.p[:, self.vertices], t)

    def coordinates_at(self, t: np.ndarray) -> np.ndarray:
        """Contact coordinates at local coordinates t (2, nq); shape (2, n, nq) (affine on a
        facet of a plane Gamma_C)."""
        return simplex_points(self.coordinate, t)

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

    @staticmethod
    def samples(n: int) -> np.ndarray:
        """Where a traction is sampled on each triangle: ``TRIANGLE_SAMPLES`` (``n``, the
        count along an edge, is for edges)."""
        return TRIANGLE_SAMPLES

    @staticmethod
    def lagrange_points(order: int) -> np.ndarray:
        return triangle_lagrange(order)[0]

    @staticmethod
    def lagrange_basis(order: int):
        return triangle_lagrange(order)[1]

    @staticmethod
    def lattice(order: int) -> tuple[np.ndarray, np.ndarray]:
        """The Lagrange nodes of P1 or P2 (P3 drawn as P2) and the sub-triangles between them."""
        nodes = triangle_lagrange(min(order, 2))[0]
        return nodes, (np.array([[0, 1, 2]]) if order == 1 else P2_CHILDREN)

    # --- nodal contact (formulations.contact.surface_nodes) ---------------------------------
    def nodes(self, order: int):
        from formulations.contact.surface_nodes import surface_nodes

        return surface_nodes(self.mesh, self, order)

    def node_rows(self, elasticity, nodes, directions: np.ndarray | None = None):
        from formulations.contact.surface_nodes import surface_rows

        return surface_rows(elasticity, nodes, directions)

    def node_pressures(self, nodes, reaction: np.ndarray) -> np.ndarray:
        from formulations.contact.surface_nodes import nodal_pressures

        return nodal_pressures(self, nodes, reaction)

    @staticmethod
    def nodal_pressure(values: np.ndarray):
        from formulations.contact.surface_nodes import surface_pressure

        return lambda t: surface_pressure(values, t)

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
    return outward(mesh, normal / np.linalg.norm(normal, axis=0), corners, element)


register_boundary(ContactSurface, "triangles: the faces of tetrahedra on Gamma_C, P1 and P2 "
                                  "nodes")

"""Triangles: the contact boundary of a tetrahedral mesh (``formulations.contact_boundary``):
triangular facets, their outer normals, quadrature on them, the location of contact
coordinates, and nodal contact on their P1 and P2 nodes (``formulations.surface_nodes``)
(docs/theory.md, section 14).

It answers the same questions as the 2D ``ContactTrace`` (``formulations.contact_edges``), with
local coordinates t of shape (2, nq) in the reference triangle (x = a + t_0 (b - a) + t_1 (c - a))
instead of (nq,) along a segment.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree
from skfem import Mesh

from formulations.contact_boundary import ContactBoundary, register_boundary
from formulations.reference_facets import (
    P2_CHILDREN,
    TRIANGLE_SAMPLES,
    barycentric,
    triangle_lagrange,
    triangle_rule,
)
from scenes.base import simplex_measures, simplex_points

DISC_DEGREE = 10  # 25 points per contact triangle for the area of the contact zone
# candidate facets per located point: the nearest centroids (in contact coordinates) tried
CANDIDATES = 8


@dataclass(frozen=True, eq=False)
class ContactSurface(ContactBoundary):
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
    name = "triangles"
    dim = 3
    kink_degree = 10  # 25 points per triangle

    @classmethod
    def of(cls, scene, mesh) -> ContactSurface:
        """The contact facets of a tetrahedral mesh (in the mesh's facet order)."""
        facets = scene.contact_facets(mesh)
        vertices = mesh.facets[:, facets]
        corners = mesh.p[:, vertices]  # (3, 3, n)
        element = mesh.f2t[0, facets]
        edges = [np.linalg.norm(corners[:, i] - corners[:, (i + 1) % 3], axis=0)
                 for i in range(3)]
        coordinate = np.asarray(scene.contact_coordinate(corners), dtype=float)
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

    def surface_tangents(self) -> list[np.ndarray]:
        """Two orthogonal unit directions in each facet: along its first edge, and n x that."""
        first = self.points(np.array([[1.0], [0.0]]))[:, :, 0] - self.points(
            np.array([[0.0], [0.0]]))[:, :, 0]
        first /= np.linalg.norm(first, axis=0)
        return [first, np.cross(self.normal, first, axis=0)]

    # --- nodal contact (formulations.surface_nodes) ------------------------------------------
    def nodes(self, order: int):
        from formulations.surface_nodes import surface_nodes

        return surface_nodes(self.mesh, self, order)

    def node_rows(self, elasticity, nodes, directions: np.ndarray | None = None):
        from formulations.surface_nodes import surface_rows

        return surface_rows(elasticity, nodes, directions)

    def node_pressures(self, nodes, reaction: np.ndarray) -> np.ndarray:
        from formulations.surface_nodes import nodal_pressures

        return nodal_pressures(self, nodes, reaction)

    @staticmethod
    def nodal_pressure(values: np.ndarray):
        from formulations.surface_nodes import surface_pressure

        return lambda t: surface_pressure(values, t)

    # --- tractions and zones ----------------------------------------------------------------
    @staticmethod
    def shear(components: np.ndarray, tangents: list[np.ndarray]) -> np.ndarray:
        """The shear vector sum_k sigma_k t_k (3, n, nq) from its components (n, nq, 2)."""
        from formulations.slack_friction import shear_vectors

        return shear_vectors(components, tangents)

    @staticmethod
    def slide_component(traction: np.ndarray) -> np.ndarray:
        """The shear traction along the obstacle's slide (x): the vector's first component."""
        return traction[0]

    @staticmethod
    def shear_vector(traction: np.ndarray) -> np.ndarray:
        """The shear traction, a vector already (3, n, nq)."""
        return traction

    def slide_vector(self, slide: float) -> np.ndarray:
        """The obstacle's slide w = slide e_x at every facet (3, n)."""
        return np.outer(np.eye(3)[0] * float(slide), np.ones(self.size))

    @staticmethod
    def ordered_breaks(coordinates: np.ndarray) -> np.ndarray:
        """A surface has no order along it: no breaks."""
        return np.zeros(0)

    @staticmethod
    def around(centre: float, radius: float) -> np.ndarray:
        """Contact coordinates (2, m) over a disc's surroundings: a grid of 201 x 201 points
        over +-2 radii about (centre, 0)."""
        line = np.linspace(-2 * radius, 2 * radius, 201)
        return np.array(np.meshgrid(centre + line, line)).reshape(2, -1)

    def zone(self, pressure) -> tuple[float, float]:
        """A 3D contact zone as (c - r, c + r): r the radius of the disc of the same area as
        the part of Gamma_C where ``pressure`` > ACTIVE_FRACTION x its maximum (by
        quadrature), c the first contact coordinate of its centroid (docs/theory.md, 14.2)."""
        from formulations.kkt import ACTIVE_FRACTION

        t, w = self.rule(DISC_DEGREE)
        values = pressure(t)
        pressed = values > ACTIVE_FRACTION * values.max(initial=0.0)
        area = self.integrate(pressed.astype(float), w).sum()
        if area <= 0:
            return float("nan"), float("nan")
        centre = self.integrate(pressed * self.coordinates_at(t)[0], w).sum() / area
        radius = float(np.sqrt(area / np.pi))
        return float(centre - radius), float(centre + radius)

    def pressure_samples(self, solution) -> tuple[np.ndarray, np.ndarray]:
        """A reference's pressure on tetrahedra: -sigma_nn(u_h) at the P2 nodes and the
        centroid of every contact triangle, clipped at 0, and 0 on the triangles where
        lambda_h is 0 throughout: the pressure of the displacement itself, not one recovered
        from the VI's nodal reactions (docs/theory.md, section 14.6). Contact coordinates
        (2, m) and values, each point once."""
        from formulations.elasticity import stress_tensor_from_gradient
        from formulations.evaluation import gradients_at

        t, nq = TRIANGLE_SAMPLES, TRIANGLE_SAMPLES.shape[1]
        x, normal = self.points(t).reshape(3, -1), self.at_points(self.normal, nq)
        grad = gradients_at(solution.elasticity.basis, solution.u, x,
                            np.repeat(self.element, nq))
        sigma = stress_tensor_from_gradient(grad, *solution.elasticity.lame)
        values = np.maximum(-np.einsum("in,ijn,jn->n", normal, sigma, normal), 0.0)
        pressed = (solution.pressure(t) > 0).any(axis=1)  # per facet: the nodal one dips to 0
        values[~np.repeat(pressed, nq)] = 0.0
        s, index = np.unique(self.coordinates_at(t).reshape(2, -1).round(14), axis=1,
                             return_index=True)
        return s, values[index]

    def pressure_at(self, pressure, s: np.ndarray, samples: int = 17) -> np.ndarray:
        """lambda_h at contact coordinates s (2, m), each in its facet: the quadratic
        interpolant of its values at the facet's six P2 nodes (exact for P1 and P2 pressures;
        for the penalty's kinked one, error O(h^2) where the kink crosses)."""
        facet, t = self.locate(s)
        nodes, basis = triangle_lagrange(2)
        values = pressure(nodes)  # (n_facets, 6)
        return np.einsum("km,km->m", values[facet].T, basis(t))

    @staticmethod
    def variation(pressure, samples: int) -> float:
        """A surface has no order along it: NaN."""
        return float("nan")

    @staticmethod
    def graded(marked: np.ndarray, n_elements: int) -> np.ndarray:
        """No grading closure on a surface: ``marked`` as it is."""
        return marked

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


register_boundary(ContactSurface, "triangles: the faces of tetrahedra on Gamma_C, P1 and P2 "
                                  "nodes")

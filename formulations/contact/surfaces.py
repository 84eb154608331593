"""What the contact boundaries of 3D bodies share (``formulations.contact.boundary``): a plane
Gamma_C with pairs of contact coordinates, tangents in each facet, shear vectors, the contact
zone as a disc and no order along Gamma_C (docs/theory.md, section 14). Triangles
(``formulations.contact.triangles``) and quadrilateral faces
(``formulations.contact.quadrilaterals``) derive from it and bring their reference facet, nodes
and point location."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from formulations.contact.boundary import ContactBoundary

DISC_DEGREE = 10  # quadrature degree on each facet for the area of the contact zone


def contact_faces(scene, mesh):
    """The contact facets of a 3D ``mesh`` (in its facet order): facet numbers, corner vertices
    (k, n), corner points (3, k, n), the cell of each and the corners' contact coordinates."""
    facets = scene.contact_facets(mesh)
    vertices = mesh.facets[:, facets]
    corners = mesh.p[:, vertices]
    coordinate = np.asarray(scene.contact_coordinate(corners), dtype=float)
    return facets, vertices, corners, mesh.f2t[0, facets], coordinate


def outward(mesh, normal: np.ndarray, corners: np.ndarray, element: np.ndarray) -> np.ndarray:
    """``normal`` (3, n) turned where it points into its cell (from the facet's centre to the
    cell's): the outer normals."""
    centroid = mesh.p[:, mesh.t[:, element]].mean(axis=1)
    inward = np.einsum("in,in->n", normal, centroid - corners.mean(axis=1)) > 0
    return np.where(inward, -normal, normal)


@dataclass(frozen=True, eq=False)
class SurfaceBoundary(ContactBoundary):
    """The shared part of a 3D body's contact boundary: its facets of ``mesh`` (``facets``),
    their corners ``vertices`` (k, n), outer unit ``normal`` (3, n), areas ``measure`` (n,),
    ``diameter`` (n,), the corners' contact coordinates ``coordinate`` (2, k, n) and the cell
    each facet belongs to (``element``)."""

    mesh: object
    facets: np.ndarray
    vertices: np.ndarray
    normal: np.ndarray
    measure: np.ndarray
    diameter: np.ndarray
    coordinate: np.ndarray
    element: np.ndarray
    dim = 3
    kink_degree = 10  # 25 points per triangle, 36 per quadrilateral

    def row_coordinates(self, t: np.ndarray) -> np.ndarray:
        """Contact coordinates (2, n * nq) of the points t of every facet, one column per row
        (facet f, point q -> f * nq + q)."""
        return self.coordinates_at(t).reshape(2, -1)

    def surface_tangents(self) -> list[np.ndarray]:
        """Two orthogonal unit directions in each facet: along its first edge, and n x that."""
        first = self.points(np.array([[1.0], [0.0]]))[:, :, 0] - self.points(
            np.array([[0.0], [0.0]]))[:, :, 0]
        first /= np.linalg.norm(first, axis=0)
        return [first, np.cross(self.normal, first, axis=0)]

    # --- tractions and zones ----------------------------------------------------------------
    @staticmethod
    def shear(components: np.ndarray, tangents: list[np.ndarray]) -> np.ndarray:
        """The shear vector sum_k sigma_k t_k (3, n, nq) from its components (n, nq, 2)."""
        from formulations.friction.slack import shear_vectors

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
        from formulations.cells.evaluation import gradients_at
        from formulations.elasticity import stress_tensor_from_gradient

        t = self.samples(0)
        nq = t.shape[1]
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
        nodes, basis = self.lagrange_points(2), self.lagrange_basis(2)
        values = pressure(nodes)  # (n_facets, k)
        return np.einsum("km,km->m", values[facet].T, basis(t))

    @staticmethod
    def variation(pressure, samples: int) -> float:
        """A surface has no order along it: NaN."""
        return float("nan")

    @staticmethod
    def graded(marked: np.ndarray, n_elements: int) -> np.ndarray:
        """No grading closure on a surface: ``marked`` as it is."""
        return marked

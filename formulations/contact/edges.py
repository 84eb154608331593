"""Edges: the contact boundary of a 2D body (``formulations.contact.boundary``), for triangles
and quadrilaterals alike (docs/theory.md, sections 1-3).

Facets are sorted by the scene's ``contact_coordinate`` and oriented so that ``start`` has the
smaller coordinate; normals are OUTER unit normals. The Lagrange nodes of P_p on an edge are
equispaced (t = k / p); their lumped mass is Newton-Cotes' (all weights positive for p <= 3).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import sparse

from formulations.cells.evaluation import evaluate_on_trace
from formulations.contact.boundary import ContactBoundary, TraceNodes, register_boundary
from formulations.contact.reference_facets import (
    facet_coordinates,
    gauss_legendre,
    lagrange_basis,
    lagrange_basis_1d,
    lagrange_nodes,
    newton_cotes,
    nodal_interpolant,
)

ZONE_SAMPLES = np.array([0.25, 0.5, 0.75])  # inside each facet: where lambda_h > 0 is contact


def outer_normals(mesh, v0: np.ndarray, v1: np.ndarray, element: np.ndarray):
    """Lengths and outer unit normals of boundary facets (v0, v1) of the given elements."""
    a, b = mesh.p[:, v0], mesh.p[:, v1]
    length = np.linalg.norm(b - a, axis=0)
    normal = np.array([b[1] - a[1], a[0] - b[0]]) / length
    centroid = mesh.p[:, mesh.t[:, element]].mean(axis=1)
    inward = np.einsum("in,in->n", normal, centroid - 0.5 * (a + b)) > 0
    normal[:, inward] *= -1.0
    return length, normal


@dataclass(frozen=True, eq=False)
class ContactTrace(ContactBoundary):
    """Contact edges of ``mesh`` ordered along Gamma_C: ``vertices`` (2, n) at the start and
    end of each, ``normal`` (2, n), ``length`` (n,), ``coordinate`` (2, n) the contact
    coordinates of start and end, ``element`` (n,) the cell each edge belongs to."""

    mesh: object
    facets: np.ndarray
    vertices: np.ndarray
    normal: np.ndarray
    length: np.ndarray
    coordinate: np.ndarray
    element: np.ndarray
    name = "edges"
    dim = 2

    @classmethod
    def of(cls, scene, mesh) -> ContactTrace:
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
        return cls(mesh=mesh, facets=facets, vertices=np.array([v0, v1]), normal=normal,
                   length=length, coordinate=np.array([s0, s1]), element=element)

    # --- the reference facet ----------------------------------------------------------------
    @property
    def measure(self) -> np.ndarray:
        return self.length

    @property
    def diameter(self) -> np.ndarray:
        return self.length

    @staticmethod
    def rule(degree: int) -> tuple[np.ndarray, np.ndarray]:
        """The Gauss-Legendre rule exact to ``degree`` (``(degree + 2) // 2`` points)."""
        return gauss_legendre((int(degree) + 2) // 2)

    @staticmethod
    def samples(n: int) -> np.ndarray:
        """n equispaced points of every facet, its ends included."""
        return np.linspace(0.0, 1.0, n)

    @staticmethod
    def lagrange_points(order: int) -> np.ndarray:
        return lagrange_nodes(order)

    @staticmethod
    def lagrange_basis(order: int):
        return lambda t: lagrange_basis_1d(order, t)

    @staticmethod
    def interpolation(points: np.ndarray, t: np.ndarray) -> np.ndarray:
        """The Lagrange polynomials on ``points`` (k,) at t; shape (k, len(t))."""
        return lagrange_basis(points, t)

    @staticmethod
    def lattice(order: int) -> tuple[np.ndarray, np.ndarray]:
        """The Lagrange nodes of P_order and the sub-intervals between them (local rows)."""
        return lagrange_nodes(order), np.array([[k, k + 1] for k in range(order)])

    def points(self, t: np.ndarray) -> np.ndarray:
        """Points at local coordinates t in [0, 1] on each facet; shape (2, n, len(t))."""
        a = self.mesh.p[:, self.vertices[0]][:, :, None]
        b = self.mesh.p[:, self.vertices[1]][:, :, None]
        return a + (b - a) * t[None, None, :]

    def coordinates_at(self, t: np.ndarray) -> np.ndarray:
        """Contact coordinates at local coordinates t on each facet; shape (n, len(t))."""
        return facet_coordinates(self.coordinate, t)

    def row_coordinates(self, t: np.ndarray) -> np.ndarray:
        """Contact coordinates of the points t of every facet, one per row (facet f, point q
        -> row f * len(t) + q): what a formulation's ``row_coordinate`` holds."""
        return self.coordinates_at(t).ravel()

    @property
    def tangent(self) -> np.ndarray:
        """Unit tangents (2, n), pointing from ``start`` to ``end``."""
        a, b = self.mesh.p[:, self.vertices[0]], self.mesh.p[:, self.vertices[1]]
        return (b - a) / self.length

    def surface_tangents(self) -> list[np.ndarray]:
        """The directions along the facets: the edge's own tangent."""
        return [self.tangent]

    # --- nodal contact ----------------------------------------------------------------------
    def nodes(self, order: int) -> TraceNodes:
        """The constraint nodes of nodal contact for P_order: the facets' vertices, then the
        p - 1 equispaced nodes inside each facet; lumped mass by Newton-Cotes."""
        vertices, local = np.unique(self.vertices, return_inverse=True)
        local = local.reshape(self.vertices.shape)  # (2, n_facets): row of each facet end
        nv, nf, inner = vertices.size, self.size, order - 1
        inside = nv + np.arange(nf * inner).reshape(nf, inner)
        facet_rows = np.column_stack([local[0], inside, local[1]])
        m = nv + nf * inner
        mass = newton_cotes(order)[None, :] * self.length[:, None]  # (n_facets, p + 1)
        weight = np.bincount(facet_rows.ravel(), mass.ravel(), m)
        normal = np.array([np.bincount(facet_rows.ravel(),
                                       (mass * self.normal[c][:, None]).ravel(), m)
                           for c in (0, 1)])
        normal /= np.linalg.norm(normal, axis=0)
        points = np.concatenate([self.mesh.p[:, vertices],
                                 self.points(lagrange_nodes(order)[1:-1]).reshape(2, -1)], axis=1)
        return TraceNodes(points=points, normal=normal, weight=weight, facet_rows=facet_rows,
                          vertices=vertices)

    def node_rows(self, elasticity, nodes: TraceNodes,
                  directions: np.ndarray | None = None) -> sparse.csr_matrix:
        """B_i = n_i' u_h(x_i): the vertex DOFs directly, the nodes inside facets by evaluating
        the basis there (other basis functions vanish at a Lagrange node up to round-off,
        dropped). ``directions`` (2, m) replaces the normals (friction's tangential rows)."""
        nv = nodes.vertices.size
        directions = nodes.normal if directions is None else directions
        dofs = elasticity.basis.nodal_dofs[:, nodes.vertices]  # (2, nv)
        vertex_rows = sparse.csr_matrix((directions[:, :nv].ravel(),
                                         (np.tile(np.arange(nv), 2), dofs.ravel())),
                                        shape=(nv, elasticity.basis.N))
        if elasticity.order == 1:
            return vertex_rows
        t_inside = lagrange_nodes(elasticity.order)[1:-1]
        inside = evaluate_on_trace(elasticity.basis, self, t_inside).matrix(directions[:, nv:])
        inside.data[np.abs(inside.data) < 1e-12] = 0.0
        inside.eliminate_zeros()
        return sparse.vstack([vertex_rows, inside], format="csr")

    @staticmethod
    def node_pressures(nodes: TraceNodes, reaction: np.ndarray) -> np.ndarray:
        """lambda at the nodes from the reactions through the lumped mass (>= 0 node by node)."""
        return reaction / nodes.weight

    @staticmethod
    def nodal_pressure(values: np.ndarray):
        """lambda_h(t) (n, nq) from its values (n, p + 1) at the facets' nodes: linear between
        them (``nodal_interpolant``)."""
        return lambda t: nodal_interpolant(values, t)

    # --- tractions and zones ----------------------------------------------------------------
    @staticmethod
    def shear(components: np.ndarray, tangents: list[np.ndarray]) -> np.ndarray:
        """The shear traction from its components (n, nq, 1) along the tangent: the scalar
        sigma_t (2D tractions are components along t)."""
        return components[..., 0]

    @staticmethod
    def slide_component(traction: np.ndarray) -> np.ndarray:
        """The shear traction along the obstacle's slide: sigma_t itself."""
        return traction

    def shear_vector(self, traction: np.ndarray) -> np.ndarray:
        """The shear traction sigma_t (n, nq) as a vector sigma_t t (2, n, nq)."""
        return traction[None] * self.tangents()[0][:, :, None]

    def slide_vector(self, slide: float) -> np.ndarray:
        """The obstacle's slide w (2, n): a 2D obstacle slides along t."""
        return float(slide) * self.tangents()[0]

    @staticmethod
    def ordered_breaks(coordinates: np.ndarray) -> np.ndarray:
        """Where a piecewise pressure may break along Gamma_C: the coordinates, sorted."""
        return np.sort(coordinates)

    @staticmethod
    def around(centre: float, half_width: float) -> np.ndarray:
        """Contact coordinates over a zone's surroundings: 8001 points over +-4 half-widths."""
        return np.linspace(centre - 4 * half_width, centre + 4 * half_width, 8001)

    def zone(self, pressure) -> tuple[float, float]:
        """End points of the union of facets where ``pressure(t)`` > ACTIVE_FRACTION x its
        maximum (an interior-point solution leaves ~1e-9 relative everywhere: not contact)."""
        from formulations.kkt import ACTIVE_FRACTION

        values = pressure(ZONE_SAMPLES)
        pressed = (values > ACTIVE_FRACTION * values.max(initial=0.0)).any(axis=1)
        if not pressed.any():
            return float("nan"), float("nan")
        return float(self.coordinate[0][pressed].min()), float(self.coordinate[1][pressed].max())

    def pressure_samples(self, solution) -> tuple[np.ndarray, np.ndarray]:
        """A reference's lambda_h sampled along Gamma_C: contact coordinates (sorted) and
        values, 9 per facet."""
        t = self.samples(9)
        s, values = self.coordinates_at(t).ravel(), solution.pressure(t).ravel()
        order = np.argsort(s, kind="stable")
        return s[order], values[order]

    def pressure_at(self, pressure, s: np.ndarray, samples: int = 17) -> np.ndarray:
        """lambda_h at contact coordinates s: located in its facet, linear between ``samples``
        equispaced values of ``pressure(t)`` per facet (exact for piecewise constant and
        linear pressures; for the penalty's kinked one, error O(h / samples)^2)."""
        s = np.asarray(s, dtype=float)
        values = pressure(self.samples(samples))
        s0, s1 = self.coordinate
        facet = np.clip(np.searchsorted(s0, s, "right") - 1, 0, s0.size - 1)
        local = np.clip((s - s0[facet]) / (s1[facet] - s0[facet]), 0.0, 1.0) * (samples - 1)
        k = np.minimum(np.floor(local).astype(int), samples - 2)
        frac = local - k
        return (1 - frac) * values[facet, k] + frac * values[facet, k + 1]

    def variation(self, pressure, samples: int) -> float:
        """TV(lambda_h) / (2 max lambda_h) along Gamma_C from ``samples`` values per facet."""
        values = pressure(self.samples(samples)).ravel()  # facets in order
        if not np.isfinite(values).all():
            return float("nan")
        peak = values.max(initial=0.0)
        if peak <= 0.0:
            return 0.0
        return float(np.abs(np.diff(np.concatenate([[0.0], values, [0.0]]))).sum()
                     / (2.0 * peak))

    def graded(self, marked: np.ndarray, n_elements: int, ratio: float = 2.0) -> np.ndarray:
        """``marked`` plus the cells of contact facets that would otherwise be more than
        ``ratio`` times longer than a neighbouring contact facet after refinement (a 2:1
        grading closure along Gamma_C).

        Why: a multiplier segment must be at least twice its longest facet (h/H <= 1/2), so an
        unrefined long facet next to a refined contact zone forces a long segment over it, and
        the estimator never marks that facet (nothing is wrong there): the mixed method's
        multiplier mesh would lag the refinement (seen on the Hertz scene). Refining such
        facets is cheap and harmless for every formulation."""
        flagged = np.zeros(n_elements, dtype=bool)
        flagged[marked] = True
        joined = np.isclose(self.coordinate[1, :-1], self.coordinate[0, 1:])  # they touch
        while True:
            after = np.where(flagged[self.element], 0.5 * self.length, self.length)
            left = np.where(np.r_[False, joined], np.r_[np.inf, after[:-1]], np.inf)
            right = np.where(np.r_[joined, False], np.r_[after[1:], np.inf], np.inf)
            too_long = ((after > ratio * np.minimum(left, right) * (1 + 1e-9))
                        & ~flagged[self.element])
            if not too_long.any():
                return np.flatnonzero(flagged)
            flagged[self.element[too_long]] = True


register_boundary(ContactTrace, "edges: the boundary edges of triangles and quadrilaterals on "
                                "Gamma_C, P1 to P3 nodes")

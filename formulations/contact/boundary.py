"""The contact boundary Gamma_C as a registered unit (docs/theory.md, sections 1 and 14).

A contact boundary is the kind of facet Gamma_C is made of: edges of a 2D body, triangles of a
tetrahedral one, quadrilaterals of a hexahedral one. Each kind is one class registered here
(``register_boundary``) and declared by the cell families whose meshes have it
(``CellFamily.contact_boundary``). Its instances hold one
mesh's contact facets in order and answer every question a formulation, an estimator or a
measurement asks of them: the reference facet and its quadrature, the Lagrange nodes and their
lumped surface mass, the normals and tangents, the constraint rows of nodal contact, the
pressure from nodal reactions, where a contact coordinate lies, the traction's samples and the
contact zone's measure. Code outside the classes never asks which kind it holds.

Local coordinates t have shape (nq,) on an edge (a point of [0, 1]) and (2, nq) on a triangle
(x = a + t_0 (b - a) + t_1 (c - a)) or a quadrilateral (bilinear on the unit square); a contact
coordinate is a number along a 2D Gamma_C and a pair (2,) on a 3D one.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy import sparse

from scenes.registry import Registry

CONTACT_BOUNDARIES = Registry("contact boundary")


@dataclass(frozen=True, eq=False)
class TraceNodes:
    """The Lagrange nodes of the displacement on Gamma_C: the facets' vertices, then the nodes
    inside them (2D: p - 1 per edge; 3D P2: the edges' midpoints; Q2 faces: the edges'
    midpoints, then the faces' centres). ``facet_rows`` (n_facets, k) gives, per facet, the
    row of each of its nodes (2D: in order of t = k / p; triangles: in ElementTriP2's order;
    quadrilaterals: in their Lagrange points' order)."""

    points: np.ndarray        # (d, m)
    normal: np.ndarray        # (d, m) unit, measure-weighted mean at a vertex
    weight: np.ndarray        # (m,) int_{Gamma_C} phi_i ds (lumped boundary mass)
    facet_rows: np.ndarray    # (n_facets, k)
    vertices: np.ndarray      # mesh vertex of each of the first rows
    edges: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))  # 3D P2: then
    # the mesh edge of each midpoint row
    faces: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))  # Q2 faces:
    # then the mesh facet of each centre row


def tangent_frame(normal: np.ndarray) -> list[np.ndarray]:
    """Unit tangents at every point, orthogonal to the normals (d, m): in 2D t = (-n_2, n_1)
    (n turned by +90 degrees); in 3D t_1 = n x e_k / |n x e_k| with e_k the axis least aligned
    with n, and t_2 = n x t_1."""
    if normal.shape[0] == 2:
        return [np.array([-normal[1], normal[0]])]
    axis = np.eye(3)[:, np.argmin(np.abs(normal), axis=0)]
    first = np.cross(normal, axis, axis=0)
    first /= np.linalg.norm(first, axis=0)
    return [first, np.cross(normal, first, axis=0)]


class ContactBoundary:
    """What every contact boundary answers from its fields (``mesh``, ``facets``,
    ``vertices``, ``normal``, ``measure``, ``diameter``, ``coordinate``, ``element``); the
    kinds fill in the rest."""

    name: str = ""
    dim: int = 2  # of the body
    # quadrature degree for integrands with kinks inside a facet (w = (g - u_hn)_- where u_hn
    # crosses g): many points on an edge; on a triangle what a 3D estimate can afford
    kink_degree: int = 19

    @property
    def size(self) -> int:
        return int(self.facets.size)

    def integrate(self, values: np.ndarray, w: np.ndarray) -> np.ndarray:
        """Per-facet integrals of ``values`` (n, nq) given at points with weights w."""
        return (values * w[None, :]).sum(axis=1) * self.measure

    def facet_breaks(self) -> np.ndarray:
        """Where a pressure piecewise on the facets may break (``ordered_breaks`` of the facets'
        ends)."""
        return self.ordered_breaks(np.append(self.coordinate[0], self.coordinate[1, -1]))

    def tangents(self) -> list[np.ndarray]:
        """The friction tangents of every facet (``tangent_frame`` of the normals)."""
        return tangent_frame(self.normal)

    def at_points(self, values: np.ndarray, nq: int) -> np.ndarray:
        """Per-facet ``values`` (k, n) repeated for each of nq points: (k, n nq)."""
        return np.repeat(values, nq, axis=1)

    def gap_derivatives(self, scene, t: np.ndarray, step: float) -> list[np.ndarray]:
        """d/dtau g (n, nq) at local coordinates t along each of ``surface_tangents()``, by
        central differences of ``step`` times the facet's diameter."""
        x = self.points(t)
        h = step * self.diameter[None, :, None]
        return [(scene.gap(x + h * tau[:, :, None]) - scene.gap(x - h * tau[:, :, None]))
                / (2 * h[0]) for tau in self.surface_tangents()]

    def interpolant_of(self, function, order: int):
        """The P_order Lagrange interpolant of ``function(x)`` (x (d, ...)) on every facet, as
        a function of local coordinates t: (n, nq)."""
        points = self.points(self.lagrange_points(order))
        values = np.asarray(function(points.reshape(points.shape[0], -1)),
                            dtype=float).reshape(self.size, -1)
        basis = self.lagrange_basis(order)
        return lambda t: values @ basis(np.asarray(t, dtype=float))


def register_boundary(cls, description: str):
    """Register the contact boundary class ``cls`` under its ``name`` (one line per kind)."""
    return CONTACT_BOUNDARIES.register(cls.name, description, dim=cls.dim)(cls)


def boundary_kind(name: str):
    """The registered class of contact boundary ``name``; ValueError naming the built ones."""
    return CONTACT_BOUNDARIES.get(name)


@dataclass(frozen=True, eq=False)
class ConformingNodes:
    """The contact nodes that are unknowns of their own (``kept``, indices into the nodes)
    and the nodal prolongation S (all nodes x kept) that gives every node's value from
    theirs: the identity on kept nodes, the hanging-node weights on the others."""

    kept: np.ndarray
    S: object  # scipy.sparse

    def weights(self, weight: np.ndarray) -> np.ndarray:
        """int phi_k of each kept node's conforming basis function sum_j S_jk phi_j."""
        return self.S.T @ weight


def conforming_nodes(elasticity, rows, m: int) -> ConformingNodes | None:
    """Which of the ``m`` contact nodes hang (docs/theory.md, section 15.4): on a 3D
    hierarchy a face's edge or centre may hold finer neighbours' nodes on Gamma_C, whose rows
    would be combinations of their parents' and whose multipliers would not be unique. None
    where none hangs. ``rows(directions)`` are the nodes' rows along given directions (d, m):
    along e_1 each picks its node's first DOF, and P says on what that DOF depends. A node
    whose value is one conforming DOF is kept (the first of several at one place: a Q2
    vertex hanging at a coarse edge's midpoint and that edge's own node)."""
    if elasticity.constraint is None:
        return None
    d = elasticity.basis.nodal_dofs.shape[0]
    on = (rows(np.repeat(np.eye(d)[:, :1], m, axis=1)) @ elasticity.constraint).tocsr()
    on.eliminate_zeros()
    single = np.flatnonzero(np.diff(on.indptr) == 1)
    single = single[np.isclose(on.data[on.indptr[single]], 1.0)]
    _, first = np.unique(on.indices[on.indptr[single]], return_index=True)
    kept = np.sort(single[first])
    if kept.size == m:
        return None
    position = np.full(on.shape[1], -1)
    position[on.indices[on.indptr[kept]]] = np.arange(kept.size)
    if (position[on.indices] < 0).any():
        raise ValueError("a hanging contact node depends on a node off Gamma_C")
    S = sparse.csr_matrix((on.data, position[on.indices], on.indptr), shape=(m, kept.size))
    return ConformingNodes(kept=kept, S=S)

"""Quadrilaterals: the contact boundary of a hexahedral mesh (``formulations.contact.boundary``),
the faces of its cells on Gamma_C (docs/theory.md, section 15.5).

A face's corners c_0..c_3 go around it (scikit-fem's order); local coordinates t in the unit
square map bilinearly, x = c_0 (1 - t_0)(1 - t_1) + c_1 t_0 (1 - t_1) + c_2 t_0 t_1
+ c_3 (1 - t_0) t_1, affinely on the parallelogram faces of a tensor grid. Nodal contact is
Q1's: the faces' corners, each with a quarter of every face's area as its lumped mass (exact for
a bilinear pressure's integral on parallelograms, and positive), the pressure bilinear between
them, so lambda_h >= 0 wherever the nodal values are. Q2 adds the edges' midpoints and the
faces' centres with Simpson's positive weights.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import sparse
from scipy.spatial import cKDTree

from formulations.contact.boundary import TraceNodes, register_boundary
from formulations.contact.reference_facets import (
    gauss_legendre,
    lagrange_basis,
    lagrange_basis_1d,
    lagrange_nodes,
)
from formulations.contact.surfaces import SurfaceBoundary, contact_faces, outward

# the unit square's corners in a face's order (2, 4)
SQUARE_CORNERS = np.array([[0.0, 1.0, 1.0, 0.0], [0.0, 0.0, 1.0, 1.0]])
CANDIDATES = 8  # faces tried per located point: the nearest centres in contact coordinates


def square_points(order: int) -> np.ndarray:
    """The Q_order Lagrange nodes of the unit square (2, (p + 1)^2), tensor order."""
    t = lagrange_nodes(order)
    return np.array(np.meshgrid(t, t, indexing="ij")).reshape(2, -1)


def square_basis(order: int):
    """basis(t) (k, nq): the Q_order Lagrange polynomials at local coordinates t (2, nq),
    the nodes in ``square_points``' order (Q1: the corners in ``SQUARE_CORNERS``' order)."""
    def basis(t: np.ndarray) -> np.ndarray:
        t = np.asarray(t, dtype=float)
        a, b = lagrange_basis_1d(order, t[0]), lagrange_basis_1d(order, t[1])
        values = (a[:, None, :] * b[None, :, :]).reshape(-1, t.shape[1])
        return values[CORNER_ORDER] if order == 1 else values

    return basis


CORNER_ORDER = np.array([0, 2, 3, 1])  # tensor nodes (0,0), (1,0), (1,1), (0,1)
# Q2's tensor nodes (square_points(2): t0 = 0, 1/2, 1 slowest): the corners in the faces'
# order, the midpoints of edges c0c1, c1c2, c2c3, c3c0, the centre at 4
Q2_CORNERS, Q2_EDGES = np.array([0, 6, 8, 2]), np.array([3, 7, 5, 1])
QUARTERS = np.full(4, 0.25)  # int of a Q1 corner function over the unit square
SIMPSON = np.outer([1, 4, 1], [1, 4, 1]).ravel() / 36  # of the Q2 ones, tensor order


def edge_index(mesh, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The mesh edge between vertices a and b (scikit-fem's edges: sorted pairs, in order)."""
    n = mesh.p.shape[1]
    keys = mesh.edges[0].astype(np.int64) * n + mesh.edges[1]
    return np.searchsorted(keys, np.minimum(a, b).astype(np.int64) * n + np.maximum(a, b))


def bilinear(corners: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Points (d, n, nq) at local coordinates t (2, nq) of quadrilaterals with corners
    (d, 4, n)."""
    phi = square_basis(1)(t)  # (4, nq)
    return np.einsum("dkn,kq->dnq", corners, phi)


@dataclass(frozen=True, eq=False)
class ContactFaces(SurfaceBoundary):
    """Contact faces of a hexahedral ``mesh``: ``vertices`` (4, n) each face's corners in
    order, ``normal`` (3, n) outer unit normals, ``measure`` (n,) areas, ``diameter`` (n,)
    the longer diagonals, ``coordinate`` (2, 4, n) the corners' contact coordinates and
    ``element`` (n,) the hexahedron of each face."""

    name = "quadrilaterals"

    @classmethod
    def of(cls, scene, mesh) -> ContactFaces:
        facets, vertices, corners, element, coordinate = contact_faces(scene, mesh)
        # half the cross product of the diagonals: the area vector of a plane face
        area = 0.5 * np.cross(corners[:, 2] - corners[:, 0], corners[:, 3] - corners[:, 1],
                              axis=0)
        measure = np.linalg.norm(area, axis=0)
        normal = outward(mesh, area / measure, corners, element)
        diameter = np.maximum(np.linalg.norm(corners[:, 2] - corners[:, 0], axis=0),
                              np.linalg.norm(corners[:, 3] - corners[:, 1], axis=0))
        return cls(mesh=mesh, facets=facets, vertices=vertices, normal=normal,
                   measure=measure, diameter=diameter, coordinate=coordinate, element=element)

    # --- the reference facet ----------------------------------------------------------------
    def points(self, t: np.ndarray) -> np.ndarray:
        """Points at local coordinates t (2, nq) on each face; shape (3, n, nq)."""
        return bilinear(self.mesh.p[:, self.vertices], np.asarray(t, dtype=float))

    def coordinates_at(self, t: np.ndarray) -> np.ndarray:
        """Contact coordinates at local coordinates t (2, nq); shape (2, n, nq)."""
        return bilinear(self.coordinate, np.asarray(t, dtype=float))

    @staticmethod
    def rule(degree: int) -> tuple[np.ndarray, np.ndarray]:
        """The tensor Gauss rule exact to ``degree`` in each variable (weights sum to 1: the
        integrals are scaled by the area, exact on parallelograms)."""
        t, w = gauss_legendre((int(degree) + 2) // 2)
        return np.array(np.meshgrid(t, t, indexing="ij")).reshape(2, -1), np.outer(w, w).ravel()

    @staticmethod
    def interpolation(points: np.ndarray, t: np.ndarray) -> np.ndarray:
        """The tensor Lagrange polynomials on a tensor grid of ``points`` (2, k) (a tensor
        rule's) at local coordinates t (2, nq); shape (k, nq)."""
        t = np.asarray(t, dtype=float)
        axes = [np.unique(points[c]) for c in range(2)]
        a, b = (lagrange_basis(axes[c], t[c]) for c in range(2))
        tensor = (a[:, None, :] * b[None, :, :]).reshape(-1, t.shape[1])
        i, j = (np.searchsorted(axes[c], points[c]) for c in range(2))
        return tensor[i * axes[1].size + j]

    @staticmethod
    def samples(n: int) -> np.ndarray:
        """Where a traction is sampled on each face: its corners, edge midpoints and centre."""
        return square_points(2)

    @staticmethod
    def lagrange_points(order: int) -> np.ndarray:
        return SQUARE_CORNERS if order == 1 else square_points(order)

    @staticmethod
    def lagrange_basis(order: int):
        return square_basis(order)

    @staticmethod
    def lattice(order: int) -> tuple[np.ndarray, np.ndarray]:
        """The Q1 corners and the two triangles between them (Q2 drawn as Q1)."""
        return SQUARE_CORNERS, np.array([[0, 1, 2], [0, 2, 3]])

    # --- nodal contact (Q1, Q2) ------------------------------------------------------------
    def nodes(self, order: int) -> TraceNodes:
        """The faces' Q_order Lagrange nodes: corners, then (Q2) the edges' midpoints and the
        faces' centres; lumped mass the integral of each node's basis function (Q1: a quarter
        of the area; Q2: Simpson's 1/36, 4/36, 16/36, positive, so lambda_i = r_i / m_i >= 0
        node by node)."""
        if order not in (1, 2):
            raise ValueError(f"order={order}: nodal contact on quadrilateral faces is Q1 or Q2")
        vertices, local = np.unique(self.vertices, return_inverse=True)
        rows = local.reshape(self.vertices.shape).T  # (n_faces, 4) in the faces' order
        points = self.mesh.p[:, vertices]
        edges, faces, mass = np.zeros(0, dtype=int), np.zeros(0, dtype=int), QUARTERS
        if order == 2:
            corners = self.vertices
            face_edges = np.array([edge_index(self.mesh, corners[k], corners[(k + 1) % 4])
                                   for k in range(4)])  # (4, n): c0c1, c1c2, c2c3, c3c0
            edges, on_edge = np.unique(face_edges, return_inverse=True)
            faces = self.facets
            tensor = np.empty((self.size, 9), dtype=np.int64)
            tensor[:, Q2_CORNERS] = rows
            tensor[:, Q2_EDGES] = vertices.size + on_edge.reshape(face_edges.shape).T
            tensor[:, 4] = vertices.size + edges.size + np.arange(self.size)
            rows, mass = tensor, SIMPSON
            points = np.concatenate([points, self.mesh.p[:, self.mesh.edges[:, edges]].mean(
                axis=1), self.mesh.p[:, corners].mean(axis=1)], axis=1)
        m = points.shape[1]
        lumped = mass[None, :] * self.measure[:, None]
        weight = np.bincount(rows.ravel(), lumped.ravel(), m)
        normal = np.array([np.bincount(rows.ravel(), (lumped * self.normal[c][:, None]).ravel(),
                                       m) for c in range(3)])
        normal /= np.linalg.norm(normal, axis=0)
        return TraceNodes(points=points, normal=normal, weight=weight, facet_rows=rows,
                          vertices=vertices, edges=edges, faces=faces)

    @staticmethod
    def node_rows(elasticity, nodes: TraceNodes,
                  directions: np.ndarray | None = None) -> sparse.csr_matrix:
        """B_i = n_i' u_h(x_i): at a Lagrange node the value is the node's own DOFs."""
        basis = elasticity.basis
        directions = nodes.normal if directions is None else directions
        dofs = basis.nodal_dofs[:, nodes.vertices]
        if nodes.edges.size:
            dofs = np.concatenate([dofs, basis.edge_dofs[:, nodes.edges],
                                   basis.facet_dofs[:, nodes.faces]], axis=1)
        m = dofs.shape[1]
        rows = sparse.csr_matrix((directions.ravel(), (np.tile(np.arange(m), 3), dofs.ravel())),
                                 shape=(m, basis.N))
        rows.eliminate_zeros()  # a plane Gamma_C: one column per node in the Schur set
        return rows

    @staticmethod
    def node_pressures(nodes: TraceNodes, reaction: np.ndarray) -> np.ndarray:
        return reaction / nodes.weight

    @staticmethod
    def nodal_pressure(values: np.ndarray):
        """lambda_h(t) (n, nq): the Q1 or Q2 interpolant of the nodes' values (n, 4 or 9)."""
        basis = square_basis(1 if values.shape[1] == 4 else 2)
        return lambda t: values @ basis(np.asarray(t, dtype=float))

    # --- location -------------------------------------------------------------------------
    def locate(self, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The face holding each contact coordinate s (2, m) and the local coordinates there
        (affine inverse on parallelograms); a point just outside Gamma_C (round-off) goes to
        the nearest face's closure."""
        s = np.asarray(s, dtype=float).reshape(2, -1)
        k = min(CANDIDATES, self.size)
        _, near = cKDTree(self.coordinate.mean(axis=1).T).query(s.T, k=k)
        near = near.reshape(s.shape[1], k).T  # (k, m)
        origin = self.coordinate[:, 0][:, near]                      # (2, k, m)
        A = np.stack([self.coordinate[:, 1] - self.coordinate[:, 0],
                      self.coordinate[:, 3] - self.coordinate[:, 0]], axis=1)  # (2, 2, n)
        local = np.einsum("ijkm,jkm->ikm", np.linalg.inv(A.transpose(2, 0, 1)).transpose(
            1, 2, 0)[:, :, near], s[:, None, :] - origin)            # (2, k, m)
        inside = np.minimum(np.minimum(local[0], local[1]), np.minimum(1 - local[0], 1 - local[1]))
        best = np.argmax(inside, axis=0)
        columns = np.arange(s.shape[1])
        return near[best, columns], np.clip(local[:, best, columns], 0.0, 1.0)


register_boundary(ContactFaces, "quadrilaterals: the faces of hexahedra on Gamma_C, Q1 and Q2 "
                                "nodes")

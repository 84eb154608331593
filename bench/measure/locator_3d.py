"""Point location in a tetrahedral mesh, for errors between solutions on different meshes in 3D
(docs/theory.md, sections 6 and 14.6).

The same method as the triangle ``Locator`` (``bench.measure.fields``): the element of the
nearest centroid (a k-d tree), then a walk across the face opposite the most negative
barycentric coordinate, all points at once. Points a walk leaves unplaced (it stopped at the
boundary of a non-convex body) are tested against the elements of their NEAREST nearest
centroids.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree
from skfem import MeshTet

from bench.measure.walk import INSIDE, element_neighbours, walk

NEAREST = 64  # elements tried per point for the points the walk left


@dataclass(frozen=True, eq=False)
class TetLocator:
    """Point location in one tetrahedral mesh (module docstring)."""

    mesh: MeshTet
    origin: np.ndarray  # (3, nE): vertex 0 of every element
    inverse: np.ndarray  # (3, 3, nE): the inverse of the affine map's matrix
    area: np.ndarray  # the volumes (named as the triangle locator's, which the error uses)

    @classmethod
    def from_mesh(cls, mesh: MeshTet) -> TetLocator:
        x = mesh.p[:, mesh.t]  # (3, 4, nE)
        jacobian = np.stack([x[:, 1] - x[:, 0], x[:, 2] - x[:, 0], x[:, 3] - x[:, 0]], axis=1)
        matrices = np.moveaxis(jacobian, -1, 0)  # (nE, 3, 3): columns are the edge vectors
        inverse = np.moveaxis(np.linalg.inv(matrices), 0, -1)
        return cls(mesh, x[:, 0], inverse, np.abs(np.linalg.det(matrices)) / 6.0)

    @functools.cached_property
    def neighbours(self) -> np.ndarray:
        return element_neighbours(self.mesh)

    @functools.cached_property
    def tree(self) -> cKDTree:
        return cKDTree(self.mesh.p[:, self.mesh.t].mean(axis=1).T)

    def reference_coordinates(self, x: np.ndarray, cells: np.ndarray) -> np.ndarray:
        """The coordinates (3, n) of points x (3, n) in the reference tetrahedron of
        ``cells``."""
        return np.einsum("rke,ke->re", self.inverse[:, :, cells], x - self.origin[:, cells])

    def barycentric(self, x: np.ndarray, cells: np.ndarray) -> np.ndarray:
        xi = self.reference_coordinates(x, cells)
        return np.vstack([1.0 - xi.sum(axis=0), xi])

    def find(self, x: np.ndarray, start: np.ndarray | None = None) -> np.ndarray:
        """The element containing each point of x (3, n), walking from the elements
        ``start`` if given; ValueError for a point outside."""
        return walk(self, x, start)

    def finish(self, x, cells, todo) -> np.ndarray:
        """The nearest centroids' elements for the points the walk left: the first that
        contains each point."""
        near = self.tree.query(x[:, todo].T, k=min(NEAREST, self.mesh.t.shape[1]))[1]
        near = near.reshape(todo.size, -1)
        placed = np.zeros(todo.size, dtype=bool)
        for column in near.T:
            bary = self.barycentric(x[:, todo], column)
            inside = ~placed & (bary.min(axis=0) >= -INSIDE)
            cells[todo[inside]] = column[inside]
            placed |= inside
        if not placed.all():
            bad = todo[np.flatnonzero(~placed)[0]]
            raise ValueError(f"point {tuple(float(c) for c in x[:, bad])} lies outside the mesh")
        return cells

"""Hierarchical quadrilateral meshes: every refinement splits a cell into four children and
records parent and children, the leaves form the current mesh, and the mesh is kept 1-irregular
(at most one hanging node per edge), as the seed paper's hierarchical meshes are
(docs/theory.md, section 15).

Every step is vectorised over cells: a refinement round splits all marked leaves at once, and
the closure that restores 1-irregularity repeats such rounds (at most one per level of the
hierarchy), never a Python loop over cells.

Cells are stored with their vertices counter-clockwise, (v0, v1, v2, v3). The children of a
cell are stored consecutively, in the order of its vertices: child k holds vertex v_k.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
from skfem import MeshQuad
from skfem.mesh import MeshQuad1

from scenes.budget import check_vertex_count
from scenes.topology import QUAD_EDGES, build_f2t, build_facets

KEY_BASE = np.int64(1) << 31  # edge key = low * KEY_BASE + high (vertex numbers below 2^31)


def edge_keys(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """One int64 per undirected edge (a, b)."""
    a, b = np.asarray(a, dtype=np.int64), np.asarray(b, dtype=np.int64)
    return np.minimum(a, b) * KEY_BASE + np.maximum(a, b)


def find_keys(keys: np.ndarray, table: tuple[np.ndarray, np.ndarray]) -> np.ndarray:
    """The value that ``table`` (sorted keys, values) holds for each key, -1 where none."""
    sorted_keys, values = table
    keys = np.asarray(keys, dtype=np.int64)
    if sorted_keys.size == 0:
        return np.full(keys.shape, -1, dtype=np.int64)
    at = np.minimum(np.searchsorted(sorted_keys, keys), sorted_keys.size - 1)
    return np.where(sorted_keys[at] == keys, values[at], -1)


class LeafCells:
    """What a hierarchy of cells (``cells``, ``first_child``) gives of its leaves: which
    cells they are, and the vertices they use with the leaves renumbered on them."""

    @property
    def leaves(self) -> np.ndarray:
        """The cells of the current mesh (in the order they were made)."""
        return np.flatnonzero(self.first_child < 0)

    def leaf_vertices(self) -> tuple[np.ndarray, np.ndarray]:
        """The hierarchy's vertices the leaves use, and the leaves renumbered on them."""
        return self._leaf_vertices

    @functools.cached_property
    def _leaf_vertices(self) -> tuple[np.ndarray, np.ndarray]:
        leaves = self.cells[:, self.leaves]
        used, local = np.unique(leaves, return_inverse=True)
        return used, local.reshape(leaves.shape)


def cell_edges(cells: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The four edges (v_k, v_k+1) of each cell: start and end vertices, each (4, n)."""
    return cells, np.roll(cells, -1, axis=0)


@dataclass(frozen=True, eq=False)
class QuadHierarchy(LeafCells):
    """Every cell ever made: ``cells`` (4, n) vertex numbers, ``parent`` (n,) (-1 for a root),
    ``first_child`` (n,) (-1 for a leaf; the children are first_child + 0..3), ``level`` (n,);
    ``split_keys`` (sorted) and ``split_midpoints`` say which edges are split, and at which
    vertex."""

    p: np.ndarray
    cells: np.ndarray
    parent: np.ndarray
    first_child: np.ndarray
    level: np.ndarray
    split_keys: np.ndarray
    split_midpoints: np.ndarray

    @classmethod
    def from_tensor(cls, xs: np.ndarray, ys: np.ndarray) -> QuadHierarchy:
        """The root cells of a tensor grid (its budget checked before it is built)."""
        xs, ys = np.asarray(xs, dtype=float), np.asarray(ys, dtype=float)
        check_vertex_count(xs.size * ys.size, f"a {xs.size - 1} x {ys.size - 1} grid")
        mesh = MeshQuad.init_tensor(xs, ys)
        return cls.from_cells(mesh.p, mesh.t)

    @classmethod
    def from_cells(cls, p: np.ndarray, cells: np.ndarray) -> QuadHierarchy:
        """Root cells (4, n), made counter-clockwise."""
        p, cells = np.asarray(p, dtype=float), np.asarray(cells, dtype=np.int64)
        a, b, d = p[:, cells[0]], p[:, cells[1]], p[:, cells[3]]
        clockwise = (b - a)[0] * (d - a)[1] - (b - a)[1] * (d - a)[0] < 0
        cells = np.where(clockwise, cells[::-1], cells)
        n = cells.shape[1]
        return cls(p, cells, np.full(n, -1), np.full(n, -1), np.zeros(n, dtype=np.int64),
                   np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64))

    def mesh(self) -> MeshQuad:
        """The leaves as a scikit-fem mesh on the vertices they use (hanging nodes included;
        ``leaf_vertices`` maps its vertices back to the hierarchy's). Built once: the mesh
        caches its facets, which every assembly on this hierarchy then shares."""
        return self._leaf_mesh

    @functools.cached_property
    def _leaf_mesh(self) -> QuadLeafMesh:
        used, local = self.leaf_vertices()
        mesh = QuadLeafMesh(np.ascontiguousarray(self.p[:, used]), np.ascontiguousarray(local),
                            hierarchy=self)
        # scikit-fem's facets, t2f and f2t, bit for bit, without its row-wise np.unique
        mesh._facets, mesh._t2f = build_facets(mesh.t, mesh.p.shape[1], QUAD_EDGES)
        mesh._f2t = build_f2t(mesh._t2f, mesh._facets.shape[1])
        return mesh

    def midpoints(self, keys: np.ndarray) -> np.ndarray:
        """The midpoint vertex of each edge key, -1 where the edge is not split."""
        return find_keys(keys, (self.split_keys, self.split_midpoints))

    def refined(self, marked: np.ndarray | None = None) -> QuadHierarchy:
        """Split the marked leaves (positions in ``leaves``; None: all of them), then as many
        more as 1-irregularity needs."""
        leaves = self.leaves
        cells = leaves if marked is None else leaves[np.asarray(marked, dtype=np.int64)]
        hierarchy = self._split(np.unique(cells))
        while True:
            extra = hierarchy.irregular_leaves()
            if extra.size == 0:
                return hierarchy
            hierarchy = hierarchy._split(extra)

    def irregular_leaves(self) -> np.ndarray:
        """Leaves with an edge split twice (a neighbour two levels finer): they must split."""
        leaves = self.leaves
        a, b = cell_edges(self.cells[:, leaves])
        middle = self.midpoints(edge_keys(a, b))
        split = middle >= 0
        twice = np.zeros(a.shape, dtype=bool)
        twice[split] = ((self.midpoints(edge_keys(a[split], middle[split])) >= 0)
                        | (self.midpoints(edge_keys(middle[split], b[split])) >= 0))
        return leaves[twice.any(axis=0)]

    def _split(self, cells: np.ndarray) -> QuadHierarchy:
        """Split the leaves ``cells`` into four children each."""
        if cells.size == 0:
            return self
        corners = self.cells[:, cells]  # (4, m)
        a, b = cell_edges(corners)
        keys = edge_keys(a, b)
        middle = self.midpoints(keys)
        new_keys, first = np.unique(keys[middle < 0], return_index=True)
        start = self.p.shape[1]
        ends_a, ends_b = a[middle < 0][first], b[middle < 0][first]
        edge_points = 0.5 * (self.p[:, ends_a] + self.p[:, ends_b])
        centres = self.p[:, corners].mean(axis=1)
        p = np.concatenate([self.p, edge_points, centres], axis=1)
        split_keys = np.concatenate([self.split_keys, new_keys])
        split_midpoints = np.concatenate([self.split_midpoints,
                                          start + np.arange(new_keys.size)])
        order = np.argsort(split_keys)
        split_keys, split_midpoints = split_keys[order], split_midpoints[order]
        at = np.searchsorted(split_keys, keys)
        m = split_midpoints[at]  # (4, m): midpoint of edge k (v_k, v_k+1)
        c = start + new_keys.size + np.arange(cells.size)
        children = np.stack([np.array([corners[k], m[k], c, m[k - 1]]) for k in range(4)],
                            axis=1)  # (4 vertices, 4 children, m)
        count = self.cells.shape[1]
        first_child = self.first_child.copy()
        first_child[cells] = count + 4 * np.arange(cells.size)
        n_new = 4 * cells.size
        return QuadHierarchy(
            p=p, cells=np.concatenate([self.cells, children.transpose(0, 2, 1).reshape(4, -1)],
                                      axis=1),
            parent=np.concatenate([self.parent, np.repeat(cells, 4)]),
            first_child=np.concatenate([first_child, np.full(n_new, -1)]),
            level=np.concatenate([self.level, np.repeat(self.level[cells] + 1, 4)]),
            split_keys=split_keys, split_midpoints=split_midpoints)

    def hanging(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The hanging nodes of the leaf mesh: each as (node, end a, end b), hierarchy vertex
        numbers, where node is the midpoint of the leaf edge (a, b) (its neighbour split)."""
        a, b = cell_edges(self.cells[:, self.leaves])
        middle = self.midpoints(edge_keys(a, b))
        split = middle >= 0
        return middle[split], a[split], b[split]


def coarse_edges(hierarchy: QuadHierarchy, cells: np.ndarray, normal: np.ndarray,
                 levels_up: int) -> np.ndarray:
    """The coarse edge (a group number) of each leaf edge: its cell's ancestor ``levels_up``
    levels above (a root has none above), and the side the edge faces."""
    ancestor = hierarchy.leaves[cells]
    for _ in range(levels_up):
        ancestor = np.where(hierarchy.parent[ancestor] >= 0, hierarchy.parent[ancestor],
                            ancestor)
    side = np.argmax(np.abs(normal), axis=0) * 2 + (normal.max(axis=0) > -normal.min(axis=0))
    return np.unique(ancestor * 4 + side, return_inverse=True)[1]


@dataclass(repr=False)
class QuadLeafMesh(MeshQuad1):
    """The leaves of a ``QuadHierarchy`` as a scikit-fem mesh that knows its hierarchy. Its
    boundary facets are the body's: scikit-fem sees each side of an edge with a hanging node
    as a boundary facet (the leaves do not share it), and those are left out, so that a
    scene's boundary predicates and loads never meet them."""

    hierarchy: QuadHierarchy | None = None

    def boundary_facets(self) -> np.ndarray:
        return self._body_boundary

    @functools.cached_property
    def _body_boundary(self) -> np.ndarray:
        facets = np.flatnonzero(self.f2t[1] == -1)
        if self.hierarchy is None:
            return facets
        used, _ = self.hierarchy.leaf_vertices()
        node, a, b = self.hierarchy.hanging()
        inner = np.concatenate([edge_keys(a, b), edge_keys(a, node), edge_keys(node, b)])
        keys = edge_keys(used[self.facets[0, facets]], used[self.facets[1, facets]])
        return facets[~np.isin(keys, inner)]

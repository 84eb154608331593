"""Hierarchical hexahedral meshes: every refinement splits a cell into eight children and
records parent and children, the leaves form the current mesh, and the mesh is kept 1-irregular
over faces and edges (at most one hanging node on any leaf's edge or face), as the
quadrilateral hierarchy is in 2D (``scenes.quad_hierarchy``; docs/theory.md, section 15.4).

A cell's vertices are stored in scikit-fem's hexahedral order, whose corners of the unit cube
are ``CORNERS``. Splitting a cell puts a lattice of 3 x 3 x 3 points on it (coordinates 0, 1,
2 along each axis): the corners, the midpoints of its 12 edges, the centres of its 6 faces and
its centre. Child k holds corner k and has vertex j at lattice point CORNERS[k] + CORNERS[j],
so the children keep the parent's orientation. A midpoint is found again by its edge's key
(the two ends), a face centre by its face's key (the smaller key of its two diagonals), so
neighbours share them. Every step is vectorised over cells.
"""

from __future__ import annotations

import functools
import itertools
from dataclasses import dataclass

import numpy as np
from skfem import MeshHex
from skfem.mesh import MeshHex1

from scenes.budget import check_vertex_count
from scenes.quad_hierarchy import LeafCells, edge_keys, find_keys

CORNERS = np.array([[0, 0, 0], [0, 1, 0], [1, 0, 0], [0, 0, 1],
                    [1, 1, 0], [0, 1, 1], [1, 0, 1], [1, 1, 1]])  # scikit-fem's local order
EDGES = ((0, 1), (0, 2), (0, 3), (1, 4), (1, 5), (2, 4), (2, 6), (3, 5), (3, 6), (4, 7),
         (5, 7), (6, 7))  # scikit-fem's RefHex.edges
FACES = ((0, 1, 4, 2), (0, 2, 6, 3), (0, 3, 5, 1), (2, 4, 7, 6), (1, 5, 7, 4),
         (3, 6, 7, 5))  # scikit-fem's RefHex.facets, corners in cyclic order


def _corner(c) -> int:
    """The local vertex at lattice point c (every coordinate 0 or 2)."""
    return int(np.flatnonzero((2 * CORNERS == np.asarray(c)).all(axis=1))[0])


def _lattice() -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The lattice points as index tables: the corner, edge and face each point is the
    corner, midpoint or centre of (-1 where not), and child k's vertices (8, 8)."""
    points = list(itertools.product(range(3), repeat=3))
    corner, edge, face = (np.full(27, -1) for _ in range(3))
    for n, c in enumerate(points):
        ones = [axis for axis in range(3) if c[axis] == 1]
        ends = [_corner([0 if axis in ones and s == 0 else (2 if axis in ones else c[axis])
                         for axis in range(3)]) for s in (0, 2)]
        if not ones:
            corner[n] = _corner(c)
        elif len(ones) == 1:
            edge[n] = EDGES.index(tuple(sorted(ends)))
        elif len(ones) == 2:
            face[n] = [set(f) for f in FACES].index(
                {_corner([ch if axis == ones[0] else cv if axis == ones[1] else c[axis]
                          for axis in range(3)]) for ch in (0, 2) for cv in (0, 2)})
    children = np.array([[points.index(tuple(CORNERS[k] + CORNERS[j])) for j in range(8)]
                         for k in range(8)])
    return corner, edge, face, children


LATTICE_CORNER, LATTICE_EDGE, LATTICE_FACE, CHILDREN = _lattice()
CENTRE = 13  # the lattice point (1, 1, 1)


def face_keys(corners: np.ndarray) -> np.ndarray:
    """One int64 per face from its corners (4, ...) in cyclic order: the smaller key of its
    two diagonals (a diagonal belongs to one face only)."""
    return np.minimum(edge_keys(corners[0], corners[2]), edge_keys(corners[1], corners[3]))


def _table(keys: np.ndarray, values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A lookup table (sorted unique keys, their values) from keys and values of one shape."""
    unique, first = np.unique(keys.ravel(), return_index=True)
    return unique, values.ravel()[first]


def _added(table: tuple[np.ndarray, np.ndarray], keys: np.ndarray, start: int):
    """``table`` with ``keys`` (unique, not in it) given the vertices start, start + 1, ..."""
    merged = np.concatenate([table[0], keys])
    vertices = np.concatenate([table[1], start + np.arange(keys.size)])
    order = np.argsort(merged)
    return merged[order], vertices[order]


def _lattice_vertices(corners, edge_key, face_key, edge_table, face_table) -> np.ndarray:
    """The lattice (27, m) of cells with ``corners`` (8, m), edge keys (12, m) and face keys
    (6, m), the midpoints and centres looked up in the tables (-1 where not split)."""
    lattice = np.full((27, corners.shape[1]), -1, dtype=np.int64)
    on_corner, on_edge, on_face = LATTICE_CORNER >= 0, LATTICE_EDGE >= 0, LATTICE_FACE >= 0
    lattice[on_corner] = corners[LATTICE_CORNER[on_corner]]
    lattice[on_edge] = find_keys(edge_key[LATTICE_EDGE[on_edge]], edge_table)
    lattice[on_face] = find_keys(face_key[LATTICE_FACE[on_face]], face_table)
    return lattice


@dataclass(frozen=True, eq=False)
class HexHierarchy(LeafCells):
    """Every cell ever made: ``cells`` (8, n) vertex numbers, ``parent`` (n,) (-1 for a root),
    ``first_child`` (n,) (-1 for a leaf; the children are first_child + 0..7), ``level``;
    ``edges`` and ``faces`` (sorted keys, vertex) hold the split edges' midpoints and the
    split faces' centres."""

    p: np.ndarray
    cells: np.ndarray
    parent: np.ndarray
    first_child: np.ndarray
    level: np.ndarray
    edges: tuple[np.ndarray, np.ndarray]
    faces: tuple[np.ndarray, np.ndarray]

    @classmethod
    def from_tensor(cls, xs, ys, zs) -> HexHierarchy:
        """The root cells of a tensor grid (its budget checked before it is built)."""
        axes = [np.asarray(a, dtype=float) for a in (xs, ys, zs)]
        check_vertex_count(int(np.prod([a.size for a in axes])),
                           " x ".join(str(a.size - 1) for a in axes) + " grid")
        mesh = MeshHex.init_tensor(*axes)
        n, empty = mesh.t.shape[1], np.zeros(0, dtype=np.int64)
        return cls(mesh.p, mesh.t.astype(np.int64), np.full(n, -1), np.full(n, -1),
                   np.zeros(n, dtype=np.int64), (empty, empty), (empty, empty))

    def mesh(self) -> HexLeafMesh:
        """The leaves as a scikit-fem mesh on the vertices they use (built once)."""
        return self._leaf_mesh

    @functools.cached_property
    def _leaf_mesh(self) -> HexLeafMesh:
        used, local = self.leaf_vertices()
        return HexLeafMesh(np.ascontiguousarray(self.p[:, used]),
                           np.ascontiguousarray(local), hierarchy=self)

    def refined(self, marked: np.ndarray | None = None) -> HexHierarchy:
        """Split the marked leaves (positions in ``leaves``; None: all), then as many more as
        1-irregularity needs."""
        leaves = self.leaves
        cells = leaves if marked is None else leaves[np.asarray(marked, dtype=np.int64)]
        hierarchy = self._split(np.unique(cells))
        while (extra := hierarchy.irregular_leaves()).size:
            hierarchy = hierarchy._split(extra)
        return hierarchy

    def irregular_leaves(self) -> np.ndarray:
        """Leaves with an edge split twice. A face split twice splits two of the leaf's edges
        twice too (every quarter of a face holds halves of two of its edges), so edges alone
        keep faces and edges 1-irregular."""
        leaves = self.leaves
        a, b = self._leaf_edges(leaves)
        middle = find_keys(edge_keys(a, b), self.edges)
        split = middle >= 0
        twice = np.zeros(a.shape, dtype=bool)
        twice[split] = ((find_keys(edge_keys(a[split], middle[split]), self.edges) >= 0)
                        | (find_keys(edge_keys(middle[split], b[split]), self.edges) >= 0))
        return leaves[twice.any(axis=0)]

    def _leaf_edges(self, cells: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        corners = self.cells[:, cells]
        return (corners[[i for i, _ in EDGES]], corners[[j for _, j in EDGES]])

    def _leaf_faces(self, cells: np.ndarray) -> np.ndarray:
        return self.cells[:, cells][np.array(FACES)]  # (6, 4, m)

    def _split(self, cells: np.ndarray) -> HexHierarchy:
        """Split the leaves ``cells`` into eight children each."""
        if cells.size == 0:
            return self
        corners = self.cells[:, cells]
        a, b = self._leaf_edges(cells)
        edge_key = edge_keys(a, b)  # (12, m)
        faces = self._leaf_faces(cells).transpose(1, 0, 2)  # (4 corners, 6 faces, m)
        face_key = face_keys(faces)  # (6, m)
        fresh = find_keys(edge_key, self.edges) < 0
        new_edges, first_edge = np.unique(edge_key[fresh], return_index=True)
        fresh_face = find_keys(face_key, self.faces) < 0
        new_faces, first_face = np.unique(face_key[fresh_face], return_index=True)
        start = self.p.shape[1]
        edge_table = _added(self.edges, new_edges, start)
        face_table = _added(self.faces, new_faces, start + new_edges.size)
        ends = np.stack([a[fresh][first_edge], b[fresh][first_edge]])
        face_corners = faces[:, fresh_face][:, first_face]
        p = np.concatenate([self.p, self.p[:, ends].mean(axis=1),
                            self.p[:, face_corners].mean(axis=1),
                            self.p[:, corners].mean(axis=1)], axis=1)
        lattice = _lattice_vertices(corners, edge_key, face_key, edge_table, face_table)
        lattice[CENTRE] = start + new_edges.size + new_faces.size + np.arange(cells.size)
        children = lattice[CHILDREN]  # (8 children, 8 vertices, m)
        count, first_child = self.cells.shape[1], self.first_child.copy()
        first_child[cells] = count + 8 * np.arange(cells.size)
        return HexHierarchy(
            p=p, cells=np.concatenate([self.cells,
                                       children.transpose(1, 2, 0).reshape(8, -1)], axis=1),
            parent=np.concatenate([self.parent, np.repeat(cells, 8)]),
            first_child=np.concatenate([first_child, np.full(8 * cells.size, -1)]),
            level=np.concatenate([self.level, np.repeat(self.level[cells] + 1, 8)]),
            edges=edge_table, faces=face_table)

    def lattice(self, cells: np.ndarray) -> np.ndarray:
        """The vertex at each of the 27 lattice points of ``cells`` (27, m): the corners, the
        midpoints of split edges and the centres of split faces, -1 where there is none (the
        centre of a leaf)."""
        corners = self.cells[:, cells]
        a, b = self._leaf_edges(cells)
        faces = self._leaf_faces(cells).transpose(1, 0, 2)
        return _lattice_vertices(corners, edge_keys(a, b), face_keys(faces), self.edges,
                                 self.faces)

    def hanging_faces(self) -> tuple[np.ndarray, np.ndarray]:
        """Centres of leaf faces that are split, each once: (node, corners (4, n))."""
        faces = self._leaf_faces(self.leaves).transpose(1, 0, 2).reshape(4, -1)
        centre = find_keys(face_keys(faces), self.faces)
        node, first = np.unique(centre[centre >= 0], return_index=True)
        return node, faces[:, centre >= 0][:, first]


@dataclass(repr=False)
class HexLeafMesh(MeshHex1):
    """The leaves of a ``HexHierarchy`` as a scikit-fem mesh that knows its hierarchy. Its
    boundary facets are the body's: a split face and the quarters on its other side are each
    seen by scikit-fem as boundary (no two leaves share them), and are left out."""

    hierarchy: HexHierarchy | None = None

    def refined(self, times_or_marked=1) -> HexLeafMesh:
        """scikit-fem's call, through the hierarchy: a number of uniform refinements, or the
        leaves to split."""
        if np.ndim(times_or_marked) > 0:
            return self.hierarchy.refined(np.asarray(times_or_marked)).mesh()
        hierarchy = self.hierarchy
        for _ in range(int(times_or_marked)):
            hierarchy = hierarchy.refined()
        return hierarchy.mesh()

    def boundary_facets(self) -> np.ndarray:
        return self._body_boundary

    def edge_between(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """The edge (a column of ``edges``) between hierarchy vertices a and b."""
        return find_keys(edge_keys(a, b), self._edge_table)

    def facet_with(self, corners: np.ndarray) -> np.ndarray:
        """The facet (a column of ``facets``) with hierarchy vertices ``corners`` (4, ...) in
        cyclic order."""
        return find_keys(face_keys(corners), self._facet_table)

    @functools.cached_property
    def _edge_table(self) -> tuple[np.ndarray, np.ndarray]:
        used, local = self.hierarchy.leaf_vertices()
        keys = edge_keys(used[local[[i for i, _ in EDGES]]], used[local[[j for _, j in EDGES]]])
        return _table(keys, self.t2e)

    @functools.cached_property
    def _facet_table(self) -> tuple[np.ndarray, np.ndarray]:
        used, local = self.hierarchy.leaf_vertices()
        return _table(face_keys(used[local[np.array(FACES)]].transpose(1, 0, 2)), self.t2f)

    @functools.cached_property
    def _body_boundary(self) -> np.ndarray:
        facets = np.flatnonzero(self.f2t[1] == -1)
        if self.hierarchy is None:
            return facets
        used, _ = self.hierarchy.leaf_vertices()
        corners = used[self.facets[:, facets]]  # scikit-fem's facets: sorted, not cyclic
        centres = self.hierarchy.hanging_faces()[0]
        split = np.zeros(facets.size, dtype=bool)
        for i, j in itertools.combinations(range(4), 2):  # one pair is the stored diagonal
            split |= find_keys(edge_keys(corners[i], corners[j]), self.hierarchy.faces) >= 0
        inner = split | np.isin(corners, centres).any(axis=0)
        return facets[~inner]

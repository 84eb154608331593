"""Hanging-node constraints of Q1 and Q2 on a 1-irregular hexahedral hierarchy
(``scenes.hex_hierarchy``; docs/theory.md, section 15.4).

A Lagrange node that lies on a leaf's boundary without being one of the leaf's own nodes
belongs to finer neighbours only: a vertex at a split edge's midpoint or a split face's centre,
and for Q2 also the midpoint of an edge and the centre of a face of those neighbours. Its value
is the leaf's field there, so every such DOF's row holds the leaf's Lagrange basis at the node's
reference point. In lattice coordinates of the leaf (0 to 4 along each axis, a quarter of the
cell each) these points are the same for every leaf: the weights are tabulated once, and only
which of them exist (their lattice points split) and their DOF numbers are looked up.

Nodes seen from two leaves (a split edge shared by several) are constrained once; a constraint
on a DOF that is itself constrained (a leaf's own node hanging on a coarser neighbour) is
substituted by ``formulations.cells.hanging_nodes.substituted``.
"""

from __future__ import annotations

import functools
import itertools

import numpy as np

from scenes.hex_hierarchy import CORNERS

LATTICE = list(itertools.product(range(3), repeat=3))  # scenes.hex_hierarchy's 27 points


def _on_one_face(points) -> bool:
    """Whether lattice points all lie on one face of the cell (a coordinate 0 or 2 shared)."""
    return any(all(p[axis] == value for p in points) for axis in range(3) for value in (0, 2))


@functools.cache
def fine_nodes(order: int) -> tuple[tuple[str, tuple[int, ...], tuple[int, int, int]], ...]:
    """Every node finer neighbours may put on a leaf's boundary: (kind, the lattice points
    that define it, its position in quarters). Vertices: the split edges' midpoints and split
    faces' centres; Q2 adds the midpoints of the edges between two adjacent lattice points and
    the centres of the faces of four."""
    nodes = [("vertex", (n,), tuple(2 * np.array(c)))
             for n, c in enumerate(LATTICE) if 1 in c and _on_one_face([c])]
    if order == 2:
        for m, n in itertools.combinations(range(27), 2):
            a, b = np.array(LATTICE[m]), np.array(LATTICE[n])
            if np.abs(a - b).sum() == 1 and _on_one_face([a, b]):
                nodes.append(("edge", (m, n), tuple(a + b)))
        for axis, value in itertools.product(range(3), (0, 2)):
            u, v = (k for k in range(3) if k != axis)
            for i, j in itertools.product(range(2), repeat=2):
                square = []
                for di, dj in ((0, 0), (1, 0), (1, 1), (0, 1)):  # cyclic
                    c = [0, 0, 0]
                    c[axis], c[u], c[v] = value, i + di, j + dj
                    square.append(LATTICE.index(tuple(c)))
                centre = [0, 0, 0]
                centre[axis], centre[u], centre[v] = 2 * value, 2 * i + 1, 2 * j + 1
                nodes.append(("face", tuple(square), tuple(centre)))
    return tuple(nodes)


def reference_weights(element, quarters: np.ndarray) -> np.ndarray:
    """The element's local basis (nodes, n) at lattice positions ``quarters`` (n, 3) of a
    cell: the position in the cell's corner geometry (``CORNERS``) taken to scikit-fem's
    reference cube by the affine map that takes corner k to its reference vertex k."""
    ref = element.refdom.p  # (3, 8)
    origin = ref[:, 0]
    axes = np.stack([ref[:, int(np.flatnonzero((CORNERS == e).all(axis=1))[0])] - origin
                     for e in np.eye(3, dtype=int)], axis=1)  # columns: the x, y, z edges
    X = origin[:, None] + axes @ (np.asarray(quarters, dtype=float).T / 4)
    weights = np.array([element.lbasis(X, i)[0] for i in range(element.doflocs.shape[0])])
    weights[np.abs(weights) < 1e-14] = 0.0  # exactly 0 off the node's edge or face
    return weights


def constraint_rows(mesh, dofs, element, order: int) -> tuple[np.ndarray, np.ndarray,
                                                              np.ndarray]:
    """(constrained DOF, DOF, weight) triplets of the scalar ``dofs`` (scikit-fem's numbering
    of ``element`` on the leaf mesh ``mesh``)."""
    hierarchy = mesh.hierarchy
    used, _ = hierarchy.leaf_vertices()
    lattice = hierarchy.lattice(hierarchy.leaves)  # (27, cells)
    nodes = fine_nodes(order)
    weights = reference_weights(element, np.array([q for _, _, q in nodes]))
    rows, cols, values, sources = [], [], [], []
    for (kind, points, _), w in zip(nodes, weights.T, strict=True):
        where = lattice[list(points)]  # (k, cells)
        cells = np.flatnonzero((where >= 0).all(axis=0))
        if cells.size == 0:
            continue
        node = _dof(mesh, dofs, kind, where[:, cells], used)
        local = np.flatnonzero(w)
        rows.append(np.repeat(node, local.size))
        cols.append(dofs.element_dofs[local][:, cells].T.ravel())
        values.append(np.tile(w[local], cells.size))
        sources.append(np.repeat(len(sources) * lattice.shape[1] + cells, local.size))
    if not rows:
        empty = np.zeros(0, dtype=np.int64)
        return empty, empty, np.zeros(0)
    return _once(*map(np.concatenate, (rows, cols, values, sources)))


def _dof(mesh, dofs, kind: str, vertices: np.ndarray, used: np.ndarray) -> np.ndarray:
    """The scalar DOF of each fine node: a vertex's, an edge's midpoint's, a face's centre's."""
    if kind == "vertex":
        return dofs.nodal_dofs[0][np.searchsorted(used, vertices[0])]
    found = (mesh.edge_between(vertices[0], vertices[1]) if kind == "edge"
             else mesh.facet_with(vertices))
    if (found < 0).any():  # every fine edge and face of a 1-irregular mesh is a leaf's
        raise ValueError(f"a finer neighbour's {kind} is missing from the leaf mesh: the "
                         "hierarchy is not 1-irregular")
    return (dofs.edge_dofs if kind == "edge" else dofs.facet_dofs)[0][found]


def _once(rows, cols, values, sources):
    """Each constrained DOF's row from the first (node kind, leaf) that gave it: another leaf
    through the same edge or face gives the same trace."""
    order = np.lexsort((sources, rows))
    rows, cols, values, sources = rows[order], cols[order], values[order], sources[order]
    start = np.r_[0, np.flatnonzero(rows[1:] != rows[:-1]) + 1]
    first = np.repeat(sources[start], np.diff(np.r_[start, rows.size]))
    keep = sources == first
    return rows[keep], cols[keep], values[keep]

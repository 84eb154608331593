"""A triangle mesh cut along the zero set of a level set (docs/theory.md, 13.2, "Where f
jumps").

Each edge whose ends lie on different sides (phi >= 0 against phi < 0) is cut where phi
changes sign along it (bisection on phi itself, so a curved zero set is followed to
round-off at the edges), and each triangle with two cut edges is split into three: the
triangle at its odd vertex and the remaining quadrilateral's two halves. A straight zero
set is then followed exactly; a curved one by its chords. Cuts within EDGE_MARGIN of an
edge's end are moved to that margin, so that no piece is thinner than a fixed share of its
triangle (a sliver of f's other side remains there, as it would without the cut).
"""

from __future__ import annotations

import numpy as np
from skfem import MeshTri

BISECTIONS = 52  # the parameter along the edge to double precision
EDGE_MARGIN = 0.05


def edge_crossings(p: np.ndarray, start: np.ndarray, end: np.ndarray, level_set
                   ) -> np.ndarray:
    """The parameter t in [EDGE_MARGIN, 1 - EDGE_MARGIN] where phi changes sign on each edge
    (start, end) (vertex indices into ``p``; the ends on different sides)."""
    a, b = p[:, start], p[:, end]
    side = level_set(a) >= 0
    lo, hi = np.zeros(start.size), np.ones(start.size)
    for _ in range(BISECTIONS):
        mid = 0.5 * (lo + hi)
        same = (level_set(a + mid * (b - a)) >= 0) == side
        lo, hi = np.where(same, mid, lo), np.where(same, hi, mid)
    return np.clip(0.5 * (lo + hi), EDGE_MARGIN, 1 - EDGE_MARGIN)


def cut_along(mesh: MeshTri, level_set) -> MeshTri:
    """``mesh`` with every triangle that the zero set of ``level_set`` crosses split into
    three along it (module docstring); the other triangles as they are."""
    p, t = mesh.p, mesh.t
    side = level_set(p) >= 0
    positive = side[t].sum(axis=0)
    crossed = np.flatnonzero((positive == 1) | (positive == 2))
    if crossed.size == 0:
        return mesh
    tc = t[:, crossed]
    sides = side[tc]
    # the vertex alone on its side: 2 if the first two agree, 1 if the first and last do
    odd = np.where(sides[0] == sides[1], 2, np.where(sides[0] == sides[2], 1, 0))
    columns = np.arange(crossed.size)
    v0, v1, v2 = (tc[(odd + shift) % 3, columns] for shift in range(3))
    edges = np.concatenate([np.sort([v0, v1], axis=0), np.sort([v0, v2], axis=0)], axis=1)
    keys = edges[0].astype(np.int64) * p.shape[1] + edges[1]
    _, first, index = np.unique(keys, return_index=True, return_inverse=True)
    start, end = edges[:, first]
    s = edge_crossings(p, start, end, level_set)
    points = p[:, start] + s * (p[:, end] - p[:, start])
    new = p.shape[1] + index.reshape(2, -1)                    # the cuts on (v0,v1), (v0,v2)
    a, b = new
    pieces = np.concatenate([[v0, a, b], [a, v1, v2], [a, v2, b]], axis=1)
    kept = np.setdiff1d(np.arange(t.shape[1]), crossed)
    return MeshTri(np.hstack([p, points]), np.hstack([t[:, kept], pieces]))

"""The energy norm of the difference of two fields on different, possibly non-nested meshes
(docs/theory.md, section 6).

The integral runs over the elements of the first field's mesh ("cells"), each cell split into
its four red children while it is larger than the element of the second mesh that contains its
centroid. So the cells resolve the finer of the two meshes everywhere, and on every cell the
first field is one polynomial exactly. The second field is taken from the element containing
the cell's centroid, its polynomial extended over the rest of the cell: exact when the first
mesh refines the second (nested levels), otherwise off by the second field's gradient jumps
across its own edges, which are of the size of *its* error. Hence: the judged solution first,
the sharper reference second. A rule of degree 2(p - 1) for the higher of the two orders is then
exact on every cell contained in one element of each mesh. On tetrahedra a cell splits into its
eight red children (four at the corners, four around a diagonal of the inner octahedron) and
"larger" compares volumes (docs/theory.md, section 14.6).
"""

from __future__ import annotations

import numpy as np
from skfem.quadrature import get_quadrature
from skfem.refdom import RefTet, RefTri

from bench.measure.discretisation_error import energy_density
from bench.measure.fields import CHUNK, GradientField

MAX_SPLITS = 40  # each split quarters a cell: 4^-40 of an element is far below any mesh


def _children(corners: np.ndarray) -> np.ndarray:
    """The four red children (2, 3, 4n) of triangles ``corners`` (2, 3, n), child-major."""
    a, b, c = corners[:, 0], corners[:, 1], corners[:, 2]
    ab, bc, ca = (a + b) / 2, (b + c) / 2, (c + a) / 2
    kids = [(a, ab, ca), (ab, b, bc), (ca, bc, c), (bc, ca, ab)]
    return np.concatenate([np.stack(kid, axis=1) for kid in kids], axis=2)


def _tet_children(corners: np.ndarray) -> np.ndarray:
    """The eight red children (3, 4, 8n) of tetrahedra ``corners`` (3, 4, n), child-major."""
    a, b, c, d = (corners[:, k] for k in range(4))
    ab, ac, ad, bc, bd, cd = (a + b) / 2, (a + c) / 2, (a + d) / 2, (b + c) / 2, (b + d) / 2, \
        (c + d) / 2
    kids = [(a, ab, ac, ad), (ab, b, bc, bd), (ac, bc, c, cd), (ad, bd, cd, d),
            (ac, bd, ab, bc), (ac, bd, bc, cd), (ac, bd, cd, ad), (ac, bd, ad, ab)]
    return np.concatenate([np.stack(kid, axis=1) for kid in kids], axis=2)


def _measure(corners: np.ndarray) -> np.ndarray:
    """Areas of triangles (2, 3, n) or volumes of tetrahedra (3, 4, n)."""
    edges = [corners[:, k] - corners[:, 0] for k in range(1, corners.shape[1])]
    if corners.shape[0] == 3:
        return np.abs(np.einsum("in,in->n", edges[0], np.cross(edges[1], edges[2], axis=0))) / 6
    a, b = edges
    return 0.5 * np.abs(a[0] * b[1] - a[1] * b[0])


def _cell_energy(first: GradientField, second: GradientField, lame, corners, area, parent,
                 located, rule) -> float:
    """sum over cells of the rule applied to sigma(e) : eps(e), e = u_first - u_second."""
    X, W = rule
    edges = [corners[:, k] - corners[:, 0] for k in range(1, corners.shape[1])]
    points = []
    for q in range(W.size):  # corner + a xi + b eta (+ c zeta), summed left to right
        point = corners[:, 0]
        for k, edge in enumerate(edges):
            point = point + edge * X[k, q]
        points.append(point)
    total = 0.0
    scale = 2.0 if corners.shape[0] == 2 else 6.0  # 1 / the reference simplex's measure
    for q, (mine, theirs) in enumerate(zip(first.at_each(points, parent),
                                           second.at_each(points, located), strict=True)):
        total += scale * W[q] * float((energy_density(mine - theirs, *lame) * area).sum())
    return total


def energy_difference(first: GradientField, second: GradientField, lame) -> float:
    """||u_first - u_second|| = a(e, e)^(1/2), integrated on cells of the first mesh refined to
    the second where that one is finer (module docstring)."""
    mesh = first.locator.mesh
    three = mesh.p.shape[0] == 3
    rule = get_quadrature(RefTet if three else RefTri, 2 * max(first.degree, second.degree))
    corners = mesh.p[:, mesh.t]
    parent = np.arange(mesh.t.shape[1])
    total, near = 0.0, None
    for depth in range(MAX_SPLITS + 1):
        # a child's centroid lies near its parent's: the walk starts from the parent's element
        located = second.locator.find(corners.mean(axis=1), near)
        area = _measure(corners)
        split = area > second.area[located]
        if depth == MAX_SPLITS:
            split[:] = False
        keep = np.flatnonzero(~split)
        for start in range(0, keep.size, CHUNK):
            block = keep[start:start + CHUNK]
            total += _cell_energy(first, second, lame, corners[:, :, block], area[block],
                                  parent[block], located[block], rule)
        if not split.any():
            break
        children = _tet_children if three else _children
        corners = children(corners[:, :, split])
        copies = corners.shape[2] // split.sum()
        parent, near = np.tile(parent[split], copies), np.tile(located[split], copies)
    return float(np.sqrt(max(total, 0.0)))

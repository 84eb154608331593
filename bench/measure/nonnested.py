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
exact on every cell contained in one element of each mesh.
"""

from __future__ import annotations

import numpy as np
from skfem.quadrature import get_quadrature
from skfem.refdom import RefTri

from bench.measure.discretisation_error import energy_density
from bench.measure.fields import CHUNK, GradientField

MAX_SPLITS = 40  # each split quarters a cell: 4^-40 of an element is far below any mesh


def _children(corners: np.ndarray) -> np.ndarray:
    """The four red children (2, 3, 4n) of triangles ``corners`` (2, 3, n), child-major."""
    a, b, c = corners[:, 0], corners[:, 1], corners[:, 2]
    ab, bc, ca = (a + b) / 2, (b + c) / 2, (c + a) / 2
    kids = [(a, ab, ca), (ab, b, bc), (ca, bc, c), (bc, ca, ab)]
    return np.concatenate([np.stack(kid, axis=1) for kid in kids], axis=2)


def _cell_energy(first: GradientField, second: GradientField, lame, corners, area, parent,
                 located, rule) -> float:
    """sum over cells of the rule applied to sigma(e) : eps(e), e = u_first - u_second."""
    X, W = rule
    a, b = corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]
    points = [corners[:, 0] + a * X[0, q] + b * X[1, q] for q in range(W.size)]
    total = 0.0
    for q, (mine, theirs) in enumerate(zip(first.at_each(points, parent),
                                           second.at_each(points, located), strict=True)):
        total += 2.0 * W[q] * float((energy_density(mine - theirs, *lame) * area).sum())
    return total


def energy_difference(first: GradientField, second: GradientField, lame) -> float:
    """||u_first - u_second|| = a(e, e)^(1/2), integrated on cells of the first mesh refined to
    the second where that one is finer (module docstring)."""
    rule = get_quadrature(RefTri, 2 * max(first.degree, second.degree))
    mesh = first.locator.mesh
    corners = mesh.p[:, mesh.t]
    parent = np.arange(mesh.t.shape[1])
    total = 0.0
    for depth in range(MAX_SPLITS + 1):
        located = second.locator.find(corners.mean(axis=1))
        a, b = corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]
        area = 0.5 * np.abs(a[0] * b[1] - a[1] * b[0])
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
        corners, parent = _children(corners[:, :, split]), np.tile(parent[split], 4)
    return float(np.sqrt(max(total, 0.0)))

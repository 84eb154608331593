"""Point location by walking, shared by the triangle and the tetrahedron locators
(docs/theory.md, sections 6.2 and 14.6): start in the element of the nearest centroid, step
across the facet opposite the most negative barycentric coordinate, all points at once; the
points a walk leaves at the boundary go to the locator's own exact finder."""

from __future__ import annotations

import numpy as np

MAX_WALK = 64  # walk steps before the remaining points go to the exact finder
INSIDE = 1e-12  # barycentric tolerance for "inside"


def element_neighbours(mesh) -> np.ndarray:
    """neighbours[k, e]: the element across the facet of e opposite its vertex k, -1 on the
    boundary (triangles or tetrahedra)."""
    f2t, t2f = mesh.f2t, mesh.t2f  # facet -> its (one or two) elements; element -> facets
    corners = mesh.t.shape[0]
    out = np.full((corners, mesh.t.shape[1]), -1)
    elements = np.arange(mesh.t.shape[1])
    for j in range(corners):
        facet = t2f[j]
        other = np.where(f2t[0, facet] == elements, f2t[1, facet], f2t[0, facet])
        on_facet = mesh.facets[:, facet]
        # the vertex of e not on facet j is the one this neighbour lies opposite to
        for k in range(corners):
            opposite = np.all([mesh.t[k] != vertex for vertex in on_facet], axis=0)
            out[k, opposite] = other[opposite]
    return out


def walk(locator, x: np.ndarray, start: np.ndarray | None = None) -> np.ndarray:
    """The element of ``locator`` containing each point of x (d, n): the walk (from the
    elements ``start``, if given: a good guess saves the nearest-centroid query), then
    ``locator.finish`` for the points it left (ValueError for a point outside)."""
    cells = (locator.tree.query(x.T, workers=-1)[1] if start is None  # all cores, sooner
             else np.array(start, dtype=np.int64))
    todo = np.arange(x.shape[1])
    for _ in range(MAX_WALK):
        bary = locator.barycentric(x[:, todo], cells[todo])
        worst = bary.argmin(axis=0)
        outside = bary[worst, np.arange(todo.size)] < -INSIDE
        step = locator.neighbours[worst[outside], cells[todo[outside]]]
        todo = todo[outside]
        if todo.size == 0:
            return cells
        stuck = step < 0  # across the boundary: left to the exact finder
        cells[todo[~stuck]] = step[~stuck]
        if stuck.all():
            break
    return locator.finish(x, cells, todo)

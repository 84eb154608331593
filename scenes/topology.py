"""Triangle-mesh topology and refinement without re-sorting (docs/theory.md, section 7).

scikit-fem builds a mesh's facets (its edges, in 2D) with ``np.unique(..., axis=1)`` on the
pairs of vertex indices, which sorts them as rows; its adaptive refinement builds them once more
for a copy of the mesh whose triangles only have their vertices reordered. Encoding an edge
(a, b), a < b, as the one integer a n_vertices + b sorts in the same order (lexicographic in
(a, b)), so the arrays here are scikit-fem's own, bit for bit, at a fraction of the cost; they
are stored where scikit-fem caches them (``_facets``, ``_t2f``, ``_f2t``), so every later use of
the mesh, ours or scikit-fem's, finds them.
"""

from __future__ import annotations

import functools
import logging
from contextlib import contextmanager
from dataclasses import dataclass, replace

import numpy as np
from skfem import MeshTri


@contextmanager
def quiet_skfem():
    """scikit-fem's tetrahedral refinement builds its mesh from non-contiguous arrays and logs a
    warning for every mesh ("Transforming over 1000 elements to C_CONTIGUOUS"): a note about
    its own speed, not about the result, which would drown a run's output."""
    logger = logging.getLogger("skfem.mesh.mesh")
    level = logger.level
    logger.setLevel(logging.ERROR)
    try:
        yield
    finally:
        logger.setLevel(level)


# a triangle's facets as pairs of its local vertices: scikit-fem's RefTri.facets
TRIANGLE_EDGES = ((0, 1), (1, 2), (0, 2))
QUAD_EDGES = ((0, 1), (1, 2), (2, 3), (0, 3))  # scikit-fem's RefQuad.facets


def build_facets(t: np.ndarray, n_vertices: int,
                 edges: tuple = TRIANGLE_EDGES) -> tuple[np.ndarray, np.ndarray]:
    """(facets, t2f): the unique edges (2, n_facets), each sorted and in lexicographic order,
    and each cell's edges (len(edges), n_elements), in the order ``edges`` (the reference
    cell's facets: ``TRIANGLE_EDGES``, ``QUAD_EDGES``)."""
    a = np.concatenate([t[i] for i, _ in edges]).astype(np.int64)
    b = np.concatenate([t[j] for _, j in edges]).astype(np.int64)
    key = np.minimum(a, b) * n_vertices + np.maximum(a, b)
    order = np.argsort(key, kind="stable")
    ordered = key[order]
    is_new = np.empty(ordered.size, dtype=bool)
    is_new[:1] = True
    np.not_equal(ordered[1:], ordered[:-1], out=is_new[1:])
    inverse = np.empty(ordered.size, dtype=np.int64)
    inverse[order] = np.cumsum(is_new) - 1
    unique = ordered[is_new]
    facets = np.vstack((unique // n_vertices, unique % n_vertices)).astype(t.dtype)
    return np.ascontiguousarray(facets), inverse.reshape(len(edges), -1)


def build_f2t(t2f: np.ndarray, n_facets: int) -> np.ndarray:
    """(2, n_facets): the triangles on either side of each facet, -1 on the boundary, as
    scikit-fem's ``Mesh.build_inverse`` gives them (the first and the last triangle met in
    ``t2f`` read row by row)."""
    position, flat = np.arange(t2f.size), t2f.ravel()
    # an assignment through repeated indices leaves the last value written (numpy's indexing
    # rules): written backwards, the first occurrence; forwards, the last
    first, last = np.empty(n_facets, dtype=np.int64), np.empty(n_facets, dtype=np.int64)
    first[flat[::-1]] = position[::-1]
    last[flat] = position
    n_elements = t2f.shape[1]
    f2t = np.vstack((first % n_elements, last % n_elements)).astype(np.int32)
    f2t[1, first == last] = -1
    return f2t


def ensure_topology(mesh: MeshTri) -> MeshTri:
    """Give a triangle mesh its facets, t2f and f2t unless it has them; returns ``mesh``.
    Other meshes are returned untouched (scikit-fem builds their topology itself)."""
    if type(mesh) is not MeshTri or hasattr(mesh, "_facets"):
        return mesh
    mesh._facets, mesh._t2f = build_facets(mesh.t, mesh.p.shape[1])
    mesh._f2t = build_f2t(mesh._t2f, mesh._facets.shape[1])
    return mesh


def longest_edge_last(mesh: MeshTri) -> tuple[np.ndarray, np.ndarray]:
    """scikit-fem's ``MeshTri1._adaptive_sort_mesh`` (vertices reordered so that (0, 2) is the
    longest edge) and the matching t2f, permuted from the mesh's own instead of rebuilt."""
    t, t2f = mesh.t, ensure_topology(mesh).t2f
    # each edge's length once, then per triangle (a - b and b - a square to the same numbers)
    a, b = mesh.p[:, mesh.facets[0]], mesh.p[:, mesh.facets[1]]
    edge_length = np.sqrt(np.sum((a - b) ** 2, axis=0))
    length = [edge_length[t2f[k]] for k in range(len(TRIANGLE_EDGES))]  # l01, l12, l02
    swap12 = (length[0] > length[2]) & (length[0] > length[1])  # (0, 1) longest
    swap01 = (length[1] > length[0]) & (length[1] > length[2])  # (1, 2) longest
    t, t2f = t.copy(), t2f.copy()
    t[[1, 2]] = np.where(swap12, t[[2, 1]], t[[1, 2]])
    t[[0, 1]] = np.where(swap01, t[[1, 0]], t[[0, 1]])
    # vertices 1 <-> 2 swapped: edges (0,1),(1,2),(0,2) become the old (0,2),(1,2),(0,1)
    t2f[[0, 2]] = np.where(swap12, t2f[[2, 0]], t2f[[0, 2]])
    # vertices 0 <-> 1 swapped: they become the old (0,1),(0,2),(1,2)
    t2f[[1, 2]] = np.where(swap01, t2f[[2, 1]], t2f[[1, 2]])
    return t, t2f


@dataclass(frozen=True, eq=False)
class RefinementPlan:
    """What ``refined(mesh, marked)`` will split, known before any new element is made: the
    mesh with each triangle's longest edge last and the facets to split (scikit-fem's closure
    of the marked triangles), or ``split`` None where scikit-fem refines by itself (uniform
    refinement, meshes with subdomains, other element types)."""

    mesh: MeshTri
    marked: np.ndarray | None
    sorted_mesh: MeshTri | None = None
    split: np.ndarray | None = None  # per facet of ``mesh``: 1 to split

    def new_vertices(self) -> int:
        return int(np.count_nonzero(self.split))

    def new_elements_per_element(self) -> np.ndarray:
        """How many more triangles each one becomes: one per split edge (green 1, blue 2,
        red 3), which is also how many new interior edges it gets."""
        return np.count_nonzero(self.split[self.sorted_mesh.t2f], axis=0)

    @functools.cached_property
    def refined(self) -> MeshTri:
        mesh, marked = self.mesh, self.marked
        if self.split is None:
            with quiet_skfem():
                return ensure_topology(mesh.refined() if marked is None
                                       else mesh.refined(marked))
        p, t, _ = MeshTri._adaptive_split_elements(self.sorted_mesh, self.split, None)
        return ensure_topology(replace(mesh, doflocs=p, t=t, _boundaries=None,
                                       _subdomains=None))


def refinement_plan(mesh: MeshTri, marked: np.ndarray | None = None) -> RefinementPlan:
    """Plan ``refined(mesh, marked)``: the closure of the marked triangles without splitting."""
    ensure_topology(mesh)
    if marked is None or type(mesh) is not MeshTri or mesh._subdomains is not None:
        return RefinementPlan(mesh, marked)
    t, t2f = longest_edge_last(mesh)
    sorted_mesh = _with_topology(replace(mesh, t=t, sort_t=False), mesh.facets, t2f)
    split = MeshTri._adaptive_find_facets(sorted_mesh, np.asarray(marked))
    return RefinementPlan(mesh, np.asarray(marked), sorted_mesh, split)


def refined(mesh: MeshTri, marked: np.ndarray | None = None) -> MeshTri:
    """``mesh.refined()`` (uniform) or ``mesh.refined(marked)`` (scikit-fem's red-green-blue
    refinement of the marked triangles and its closure), the same mesh to the bit, with the
    topology of both meshes built here."""
    return refinement_plan(mesh, marked).refined


def _with_topology(mesh: MeshTri, facets: np.ndarray, t2f: np.ndarray) -> MeshTri:
    mesh._facets, mesh._t2f = facets, t2f
    return mesh

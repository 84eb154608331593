"""Multiplier patches of a 3D contact surface: the coarser contact mesh of the mixed method on
tetrahedra (docs/theory.md, section 14.7).

A piecewise constant lambda_H on patches of contact triangles is inf-sup stable against the
normal trace of P1 displacements when every patch contains the whole star of a vertex whose
normal displacement is free (the macro-element condition, Stenberg 1984): the test function
phi_z n of that vertex z then lives inside the patch and has a positive mean on it. The
``star`` patches meet the condition on any mesh, uniform or adaptive: a maximal independent
set of such vertices (no two on one triangle, so their stars are disjoint), each star a patch,
and every other triangle joined to a patch it shares a vertex with. ``triangle`` patches (the
trace mesh itself) do not meet it: with about twice as many triangles as vertices, B' has a
kernel and beta_h = 0.
"""

from __future__ import annotations

import numpy as np
from scipy import sparse

STAR_SEED = 0  # the tie-break permutation of the independent set (fixed: the patches of a
# mesh are reproducible)
MIN_STAR = 4  # triangles around a centre: h / H <= 1/2 for equal triangles (a corner's star of
# one triangle would be a patch as fine as the trace mesh)


def free_normal_vertices(surface, nodal_dofs: np.ndarray, free: np.ndarray) -> np.ndarray:
    """Per mesh vertex, whether phi_z n is an admissible displacement for every contact normal
    n at z: each displacement component that n has is free (not on Gamma_D)."""
    is_free = np.zeros(int(max(nodal_dofs.max(), free.max(initial=0))) + 1, dtype=bool)
    is_free[free] = True
    component = np.zeros(nodal_dofs.shape[::-1])  # (n_vertices, 3): the largest |n_c| at z
    for corner in surface.vertices:
        np.maximum.at(component, corner, np.abs(surface.normal.T))
    return ~((component.T > 1e-12) & ~is_free[nodal_dofs]).any(axis=0)


def independent_vertices(vertices: np.ndarray, candidate: np.ndarray,
                         priority: np.ndarray) -> np.ndarray:
    """A maximal set of ``candidate`` vertices no two of which share a triangle (``vertices``:
    (3, n) corners), lowest ``priority`` first among neighbours (Luby's rounds, vectorised:
    a vertex is taken when it beats every undecided neighbour; a few rounds suffice)."""
    i = np.concatenate([vertices[a] for a in range(3) for b in range(3) if a != b])
    j = np.concatenate([vertices[b] for a in range(3) for b in range(3) if a != b])
    state = np.where(candidate, 0, -1)  # 0 undecided, 1 taken, -1 left out
    while (state == 0).any():
        both = (state[i] == 0) & (state[j] == 0)
        best = priority.copy()
        np.minimum.at(best, i[both], priority[j[both]])
        taken = (state == 0) & (best == priority)
        state[taken] = 1
        state[i[taken[j] & (state[i] == 0)]] = -1
    return state == 1


def star_patches(surface, admissible: np.ndarray) -> np.ndarray:
    """Patch index of every contact triangle (module docstring): stars of an independent set
    of ``admissible`` vertices with at least ``MIN_STAR`` triangles, vertices of many triangles
    first, the rest joined by vertex."""
    v = surface.vertices
    n_vertices = surface.mesh.p.shape[1]
    on_surface = np.zeros(n_vertices, dtype=bool)
    on_surface[v.ravel()] = True
    valence = np.bincount(v.ravel(), minlength=n_vertices)
    tie = np.random.default_rng(STAR_SEED).permutation(n_vertices)
    centre = independent_vertices(v, on_surface & admissible & (valence >= MIN_STAR),
                                  -valence * n_vertices + tie)
    patch_of_centre = np.cumsum(centre) - 1
    hits = centre[v]  # (3, n): at most one corner per triangle is a centre
    patch = np.full(v.shape[1], -1)
    has = hits.any(axis=0)
    patch[has] = patch_of_centre[v[hits.argmax(axis=0), np.arange(v.shape[1])]][has]
    return join_by_vertex(v, patch, n_vertices)


def join_by_vertex(vertices: np.ndarray, patch: np.ndarray, n_vertices: int) -> np.ndarray:
    """Give every triangle without a patch (-1) a patch it shares a vertex with; triangles out
    of reach of any patch get their own."""
    patch = patch.copy()
    while (patch < 0).any():
        of_vertex = np.full(n_vertices, -1)
        np.maximum.at(of_vertex, vertices[:, patch >= 0].ravel(),
                      np.tile(patch[patch >= 0], 3))
        joined = np.where(patch < 0, of_vertex[vertices].max(axis=0), patch)
        if np.array_equal(joined, patch):
            left = patch < 0
            joined[left] = patch.max() + 1 + np.arange(left.sum())
        patch = joined
    return np.unique(patch, return_inverse=True)[1]


def patches(surface, kind: str, admissible: np.ndarray) -> np.ndarray:
    """Patch index of every contact triangle: ``kind`` "star" (``star_patches``) or
    "triangle" (each triangle its own patch)."""
    if kind == "triangle":
        return np.arange(surface.size)
    return star_patches(surface, admissible)


def patch_sizes(surface, patch: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Area |P| and size H_P = |P|^(1/2) of every patch (the 2D segment length's analogue: a
    triangle's h / H is then (|T| / |P|)^(1/2), 1 for the trace mesh, 1/2 for four equal
    triangles; a diameter would not do, as two right triangles make a square as wide as
    either's hypotenuse)."""
    area = np.bincount(patch, weights=surface.measure)
    return area, np.sqrt(area)


def patch_sum(patch: np.ndarray, columns_per_facet: int) -> sparse.csr_matrix:
    """S with (S v)_P = sum of v over the ``columns_per_facet`` entries of every facet in P."""
    n = patch.size * columns_per_facet
    return sparse.csr_matrix((np.ones(n), (np.repeat(patch, columns_per_facet), np.arange(n))),
                             shape=(int(patch.max()) + 1, n))

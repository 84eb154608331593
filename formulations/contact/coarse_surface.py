"""The contact surface one level coarser: the multiplier mesh of the 3D mixed method, as the
seed's T_{C,H} with h/H = 1/2 is in 2D (docs/theory.md, section 19.2).

A tetrahedral mesh keeps no refinement history, but its vertices keep their age: scikit-fem
numbers the new vertices of a refinement after the old ones. The **coarse vertices** C are a
maximal set of contact-surface vertices no two of which share a contact triangle, oldest first.
On a uniformly refined mesh that is exactly the vertex set of the surface before the last
refinement (each old vertex only touches new ones, and each new vertex is an old edge's
midpoint); on a bisection-refined (adaptive) mesh it is the analogous one-level-coarser set.

* **P1 multipliers** (continuous, piecewise linear on the coarse surface): the coarse hat of
  Z in C is psi_Z = sum_z P_zZ phi_z over the fine surface hats, P_ZZ = 1 and P_zZ = 1 / n_z
  for a vertex z outside C with n_z neighbours in C. On a uniformly refined mesh every z
  outside C is the midpoint of the coarse edge between its two neighbours in C, so psi_Z is
  the coarse mesh's P1 hat exactly. psi_Z >= 0 and sum_Z psi_Z = 1: mu_H = sum mu_Z psi_Z is
  non-negative wherever its coefficients are.
* **P0 multipliers** on the coarse triangles: the triangles with no vertex in C are the
  coarse triangles' middles; each triangle with one vertex in C (none has two) joins the
  middle across its edge opposite that vertex. On a uniformly refined mesh these are the
  coarse triangles, four fine ones each (h/H = 1/2); what is left on a graded mesh joins a
  patch it shares a vertex with.
"""

from __future__ import annotations

import numpy as np
from scipy import sparse

from formulations.contact.patches import independent_vertices, join_by_vertex


def coarse_vertices(vertices: np.ndarray, n_vertices: int) -> np.ndarray:
    """Whether each mesh vertex is a coarse vertex of the surface with corners ``vertices``
    (3, n): independent, oldest (lowest index) first (module docstring)."""
    on_surface = np.zeros(n_vertices, dtype=bool)
    on_surface[vertices.ravel()] = True
    return independent_vertices(vertices, on_surface, np.arange(n_vertices))


def surface_edges(vertices: np.ndarray) -> np.ndarray:
    """The distinct edges (2, m) of the triangles ``vertices`` (3, n), lower index first."""
    pairs = np.hstack([vertices[[a, (a + 1) % 3]] for a in range(3)])
    return np.unique(np.sort(pairs, axis=0), axis=1)


def coarse_hats(vertices: np.ndarray, coarse: np.ndarray) -> sparse.csr_matrix:
    """P (n_vertices x n_coarse) with psi_Z = sum_z P_zZ phi_z (module docstring); columns in
    the order of the coarse vertices' indices."""
    n_vertices = coarse.size
    column = np.cumsum(coarse) - 1
    i, j = surface_edges(vertices)
    # each edge from a fine vertex to a coarse one: both directions
    fine = np.concatenate([i[coarse[j] & ~coarse[i]], j[coarse[i] & ~coarse[j]]])
    to = np.concatenate([j[coarse[j] & ~coarse[i]], i[coarse[i] & ~coarse[j]]])
    count = np.bincount(fine, minlength=n_vertices)
    Z = np.flatnonzero(coarse)
    rows = np.concatenate([Z, fine])
    cols = np.concatenate([column[Z], column[to]])
    vals = np.concatenate([np.ones(Z.size), 1.0 / count[fine]])
    return sparse.csr_matrix((vals, (rows, cols)), shape=(n_vertices, Z.size))


def coarse_triangles(vertices: np.ndarray, coarse: np.ndarray) -> np.ndarray:
    """Patch index of every triangle: the coarse triangles of the module docstring."""
    n = vertices.shape[1]
    hits = coarse[vertices]  # (3, n)
    middle = ~hits.any(axis=0)
    patch = np.full(n, -1)
    patch[middle] = np.arange(int(middle.sum()))
    # the edge opposite each corner, keyed by its sorted end points
    opposite = np.sort(np.stack([vertices[(a + 1) % 3] for a in range(3)]
                                + [vertices[(a + 2) % 3] for a in range(3)]).reshape(2, 3, n),
                       axis=0)
    key = opposite[0] * coarse.size + opposite[1]  # (3, n)
    middle_key = key[:, middle].ravel()
    order = np.argsort(middle_key)
    middle_key, middle_patch = middle_key[order], np.tile(patch[middle], 3)[order]
    one = np.flatnonzero(hits.any(axis=0))
    if middle_key.size:
        across = key[hits.argmax(axis=0)[one], one]
        at = np.minimum(np.searchsorted(middle_key, across), middle_key.size - 1)
        patch[one] = np.where(middle_key[at] == across, middle_patch[at], -1)
    return join_by_vertex(vertices, patch, coarse.size)

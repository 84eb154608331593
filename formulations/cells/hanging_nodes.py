"""Hanging-node constraints of Q1 and Q2 on a 1-irregular quadrilateral hierarchy
(``scenes.quad_hierarchy``; docs/theory.md, section 15).

A sparse matrix P maps the conforming DOFs to every cell DOF of the leaf mesh: a DOF at a
hanging node, or inside an edge that is half of a coarser leaf's edge, takes the value the
coarse edge's trace gives it there, so P u is continuous across every edge. Systems are then
formed as Galerkin systems in the conforming space: P' K P, P' F, contact rows B P.

Along a coarse edge from a (t = 0) to b (t = 1) with hanging node m (t = 1/2):

* Q1: the trace is linear, u(m) = (u_a + u_b) / 2;
* Q2: the trace is quadratic with nodes u_a, u_e (the edge's midpoint DOF), u_b, so
  u(m) = u_e, and the midpoints of the halves (t = 1/4, 3/4) take
  3/8 u_a + 3/4 u_e - 1/8 u_b and -1/8 u_a + 3/4 u_e + 3/8 u_b.
"""

from __future__ import annotations

import numpy as np
from scipy import sparse
from skfem import Basis

from scenes.quad_hierarchy import QuadHierarchy, edge_keys

QUARTER = np.array([3 / 8, 3 / 4, -1 / 8])  # weights of u_a, u_e, u_b at t = 1/4


def constraint_rows(hierarchy: QuadHierarchy, basis: Basis) -> tuple[np.ndarray, np.ndarray,
                                                                       np.ndarray]:
    """The constraints as (constrained DOF, DOF, weight) triplets on ``basis`` (a vector Q1 or
    Q2 basis on ``hierarchy.mesh()``): constrained = sum of weight x DOF."""
    used, _ = hierarchy.leaf_vertices()
    node, a, b = (np.searchsorted(used, v) for v in hierarchy.hanging())
    rows, cols, weights = [], [], []
    nodal = basis.nodal_dofs  # (components, vertices)
    if basis.facet_dofs.size == 0:  # Q1
        for component in nodal:
            rows += [component[node]] * 2
            cols += [component[a], component[b]]
            weights += [np.full(node.size, 0.5)] * 2
    else:  # Q2: the coarse edge's midpoint DOF, and the halves' midpoint DOFs
        mesh = basis.mesh
        keys = edge_keys(mesh.facets[0], mesh.facets[1])
        order = np.argsort(keys)

        def facet(u, v):
            return order[np.searchsorted(keys[order], edge_keys(u, v))]

        coarse, first, second = facet(a, b), facet(a, node), facet(node, b)
        for c, component in enumerate(nodal):
            edge = basis.facet_dofs[c]
            rows.append(component[node])
            cols.append(edge[coarse])
            weights.append(np.ones(node.size))
            for half, (wa, we, wb) in ((first, QUARTER), (second, QUARTER[::-1])):
                rows += [edge[half]] * 3
                cols += [component[a], edge[coarse], component[b]]
                weights += [np.full(node.size, wa), np.full(node.size, we),
                            np.full(node.size, wb)]
    if not rows:
        empty = np.zeros(0, dtype=np.int64)
        return empty, empty, np.zeros(0)
    return np.concatenate(rows), np.concatenate(cols), np.concatenate(weights)


def prolongation(hierarchy: QuadHierarchy, basis: Basis) -> tuple[sparse.csr_matrix,
                                                                  np.ndarray]:
    """P (basis.N x conforming DOFs) and the conforming DOFs of ``basis`` on ``hierarchy``."""
    return substituted(*constraint_rows(hierarchy, basis), basis.N)


def substituted(rows: np.ndarray, cols: np.ndarray, weights: np.ndarray,
                n: int) -> tuple[sparse.csr_matrix, np.ndarray]:
    """P (n x conforming DOFs) and the conforming DOFs (sorted) from constraints given as
    (constrained DOF, DOF, weight) triplets. A constraint on a DOF that is itself constrained
    is substituted until none is left (on a 1-irregular mesh a few times at most: an edge's
    end may hang on a coarser edge or face)."""
    constrained = np.zeros(n, dtype=bool)
    constrained[rows] = True
    kept = np.flatnonzero(~constrained)
    step = sparse.csr_matrix((np.concatenate([np.ones(kept.size), weights]),
                              (np.concatenate([kept, rows]), np.concatenate([kept, cols]))),
                             shape=(n, n))
    full = step
    for _ in range(4):  # chains of constraints: substitute again
        if not full[:, constrained].nnz:
            break
        full = (full @ step).tocsr()
    if full[:, constrained].nnz:
        raise ValueError("the hanging-node constraints form a chain longer than 4: the mesh "
                         "is not 1-irregular")
    return full[:, kept].tocsr(), kept

"""The load vector (f, v) of a body force that may be only piecewise smooth (docs/theory.md,
section 9).

A Gauss rule integrates a body force that jumps inside an element with an error of order
|T| [f] whatever its degree, which in the energy norm is an O(h) consistency error along the
jump: harmless for P1 (its own error is O(h)), but it stops P2 and P3 from converging (measured
on ``free-boundary``, whose f jumps across |x| = a: the P3 energy error at 74 112 DOFs is
8.1e-5 with scikit-fem's rule and 1.5e-5 with a rule of order 19). So the rule is refined
adaptively where f is rough: a (sub-)triangle whose rule and the same rule on its four children
disagree about int f by more than ROUGH_TOLERANCE max|f| |T| is split, up to MAX_DEPTH times
(the jump's error then shrinks like 2^-depth); elsewhere the element's own rule stays. On
tetrahedra the same with eight children (the red refinement: four corner tetrahedra and the
inner octahedron cut along one diagonal into four, the diagonal chosen by the global vertex
numbers so that the rule does not depend on the order an element lists its vertices in),
down to MAX_DEPTH_3D only: 8^depth children per rough element (measured on
``free-boundary-3d``, vi, P2, uniform: the energy error at 13 872 DOFs is 9.53e-4 with
scikit-fem's rule, 8.97e-4 / 9.07e-4 / 8.96e-4 with depth 1 / 2 / 3, the load taking 0.8 /
1.0 / 3.2 s; depth 5 took 90 s).
"""

from __future__ import annotations

import numpy as np
from skfem import Basis, LinearForm, asm
from skfem.helpers import dot

from formulations.cells.evaluation import evaluate_at

MAX_DEPTH = 5  # a rough element ends in sub-triangles down to 1/32 of its size
MAX_DEPTH_3D = 2  # tetrahedra: 8^depth children each; see the module docstring
ROUGH_TOLERANCE = 1e-4
CHUNK = 100_000  # points per block when adding the refined rule's contributions
_REFERENCE = {2: np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]),
              3: np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])}
# the red refinement of a tetrahedron (0, 1, 2, 3) as corners among its vertices (0-3) and
# edge midpoints (4: 01, 5: 02, 6: 03, 7: 12, 8: 13, 9: 23); the octahedron cut along 5-8
TET_CHILDREN = np.array([[0, 4, 5, 6], [4, 1, 7, 8], [5, 7, 2, 9], [6, 8, 9, 3],
                         [4, 5, 6, 8], [4, 5, 7, 8], [5, 6, 8, 9], [5, 7, 8, 9]])
TET_MIDPOINTS = ((0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3))


def children(corners: np.ndarray) -> np.ndarray:
    """The 2^d sub-simplices (2^d n, d + 1, d) of triangles or tetrahedra ``corners``
    (n, d + 1, d) (reference coordinates), children of simplex i at rows 2^d i onwards."""
    if corners.shape[2] == 3:
        nodes = np.concatenate([corners] + [(corners[:, i:i + 1] + corners[:, j:j + 1]) / 2
                                            for i, j in TET_MIDPOINTS], axis=1)  # (n, 10, 3)
        return nodes[:, TET_CHILDREN].reshape(-1, 4, 3)
    a, b, c = corners[:, 0], corners[:, 1], corners[:, 2]
    ab, bc, ca = (a + b) / 2, (b + c) / 2, (c + a) / 2
    return np.stack([np.stack(s, axis=1) for s in
                     ((a, ab, ca), (ab, b, bc), (ca, bc, c), (bc, ca, ab))], axis=1).reshape(
        -1, 3, 2)


def mapped_rule(corners: np.ndarray, rule) -> tuple[np.ndarray, np.ndarray]:
    """The reference rule on every sub-simplex: points (d, n, nq) (reference coordinates of
    the parent element) and weights (n, nq)."""
    X, W = rule
    a = corners[:, 0]
    if corners.shape[2] == 3:
        edges = corners[:, 1:] - a[:, None]  # (n, 3, 3): edge k of tetrahedron i
        points = a.T[:, :, None] + np.einsum("nkd,kq->dnq", edges, X)
        return points, np.abs(np.linalg.det(edges))[:, None] * W
    e1, e2 = corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]
    points = a.T[:, :, None] + e1.T[:, :, None] * X[0] + e2.T[:, :, None] * X[1]
    return points, np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])[:, None] * W


def integrals(body_force, mapping, cells, corners, rule) -> np.ndarray:
    """int f over sub-simplices (d, n) of elements ``cells``."""
    X, W = mapped_rule(corners, rule)
    det = np.abs(mapping.detDF(np.zeros((X.shape[0], 1)), tind=cells))[:, 0]
    return (body_force(physical(mapping, cells, X)) * (W * det[:, None])).sum(axis=-1)


def shared_integrals(body_force, mapping, cells, corners, rule) -> np.ndarray:
    """int f over the same sub-simplices ``corners`` (m, d + 1, d) of every element of
    ``cells``: (d, n m), sub-simplex j of element i at column m i + j (``integrals`` with the
    rule mapped once, not once per element)."""
    X, W = mapped_rule(corners, rule)                                   # (d, m, nq), (m, nq)
    det = np.abs(mapping.detDF(np.zeros((X.shape[0], 1)), tind=cells))[:, 0]
    A, b = mapping.A[:, :, cells], mapping.b[:, cells]
    x = np.einsum("ijn,jq->inq", A, X.reshape(X.shape[0], -1)) + b[:, :, None]
    values = body_force(x).reshape(X.shape[0], cells.size, *W.shape)
    return (values * (W[None] * det[:, None, None])).sum(axis=-1).reshape(X.shape[0], -1)


def physical(mapping, cells, X: np.ndarray) -> np.ndarray:
    """Physical points (d, n, nq) of reference points X (d, n, nq), row i in element cells[i]."""
    A, b = mapping.A[:, :, cells], mapping.b[:, cells]
    return np.einsum("ijn,jnq->inq", A, X) + b[:, :, None]


def first_children(body_force, mapping, t: np.ndarray, rule):
    """Every element's corners in ascending global vertex order (n, d + 1, d), and int f over
    their 2^d children (d, n 2^d). Red refinement of a tetrahedron depends on the order of its
    corners (the octahedron's diagonal), so ordering them by global number makes the rule the
    same on any mesh whose elements list the same vertices in another order (the estimators'
    ``sorted_tetrahedra``). One mapped rule per vertex permutation: at most (d + 1)! groups."""
    d, n = t.shape[0] - 1, t.shape[1]
    order = np.argsort(t, axis=0, kind="stable").T
    permutations, group = np.unique(order, axis=0, return_inverse=True)
    group = group.ravel()
    parts = np.empty((d, n, 2**d))
    for g, permutation in enumerate(permutations):
        cells = np.flatnonzero(group == g)
        reference = children(_REFERENCE[d][permutation][None])
        parts[:, cells] = shared_integrals(body_force, mapping, cells, reference,
                                           rule).reshape(d, cells.size, -1)
    return _REFERENCE[d][order], parts.reshape(d, -1)


def refined_rule(body_force, basis: Basis, max_depth: int | None = None):
    """The rough elements, and the adaptive rule on them as a list of (cells, corners): the
    sub-triangles (corners in the reference coordinates of element ``cells[i]``) that keep the
    element's rule (module docstring), split at most ``max_depth`` times (default MAX_DEPTH,
    MAX_DEPTH_3D on tetrahedra)."""
    mapping, rule = basis.mapping, basis.quadrature
    n, d = basis.mesh.t.shape[1], basis.mesh.dim()
    if max_depth is None:
        max_depth = MAX_DEPTH if d == 2 else MAX_DEPTH_3D
    k, volume = 2**d, 1.0 / (2 if d == 2 else 6)  # children per simplex; reference measure
    cells = np.arange(n)
    scale = np.abs(body_force(np.asarray(basis.global_coordinates()))).max()
    whole = shared_integrals(body_force, mapping, cells, _REFERENCE[d][None], rule)
    kept, rough = [], None
    for depth in range(max_depth + 1):
        if cells.size == 0:
            break
        if depth == 0:   # grouped by vertex order: one mapped rule per group
            corners, parts = first_children(body_force, mapping, basis.mesh.t, rule)
        else:
            sub = children(corners)
            parts = integrals(body_force, mapping, np.repeat(cells, k), sub, rule)
        area = np.abs(mapping.detDF(np.zeros((d, 1)), tind=cells))[:, 0] * volume / k**depth
        split = (np.abs(whole - parts.reshape(d, -1, k).sum(axis=-1)).max(axis=0)
                 > ROUGH_TOLERANCE * scale * area)
        if depth == 0:
            rough = cells[split]
        if depth == max_depth:
            split[:] = False
        kept.append((cells[~split], corners[~split]) if depth else None)  # depth 0: skfem's
        cells = np.repeat(cells[split], k)
        corners = (children(corners[split]) if depth == 0
                   else sub.reshape(-1, k, d + 1, d)[split].reshape(-1, d + 1, d))
        whole = parts.reshape(d, -1, k)[:, split].reshape(d, -1)  # the children's own integrals
    kept = kept[1:]
    return rough, kept


def body_load(body_force, basis: Basis, max_depth: int | None = None) -> np.ndarray:
    """(f, v) for every basis function, the rough elements on the refined rule (split at most
    ``max_depth`` times, as in ``refined_rule``)."""
    @LinearForm
    def form(v, w):
        return dot(body_force(w.x), v)

    F = asm(form, basis)
    rough, kept = refined_rule(body_force, basis, max_depth)
    if rough.size == 0 or not kept:  # max_depth 0: every element keeps its own rule
        return F
    F -= asm(form, Basis(basis.mesh, basis.elem, quadrature=basis.quadrature, elements=rough))
    d = basis.mesh.dim()
    det = np.abs(basis.mapping.detDF(np.zeros((d, 1))))[:, 0]
    for cells, corners in kept:
        X, W = mapped_rule(corners, basis.quadrature)
        x = physical(basis.mapping, cells, X).reshape(d, -1)
        fw = body_force(x) * (W * det[cells, None]).ravel()
        at = np.repeat(cells, W.shape[1])
        for start in range(0, at.size, CHUNK):
            block = slice(start, start + CHUNK)
            values = evaluate_at(basis, x[:, block], at[block]).values
            dofs = basis.element_dofs[:, at[block]]
            for k, v in enumerate(values):
                F += np.bincount(dofs[k], (v * fw[:, block]).sum(axis=0), F.size)
    return F

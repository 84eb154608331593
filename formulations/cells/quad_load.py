"""The load (f, v) of a body force that may jump inside a tensor-product cell, a quadrilateral
or a hexahedron (docs/theory.md, sections 9 and 15): as ``formulations.cells.load`` does on
simplices, a cell whose rule and the same rule on its 2^d sub-boxes disagree about int f by
more than ROUGH_TOLERANCE max|f| |T| is split, up to MAX_DEPTH times, and integrated on the
sub-boxes that agree; elsewhere the cell keeps its own rule. Without this the O(h) consistency
error along the jump stops Q2 from converging (measured on ``free-boundary``: the adaptive Q2
error rose from 7.5e-5 to 1.1e-4 between 7 288 and 12 752 DOFs with the cell rule alone; on
hexahedra of ``free-boundary-3d`` the cell rule's contact force moved 0.0017, 0.0009, 0.0022
from 300 to 13 872 DOFs, the refined one's 0.0015, 0.0022, 0.0023).

The cells are parallelograms or parallelepipeds (x = v0 + A xi), so a sub-box's points and
the reference basis functions there are those of the reference cell.
"""

from __future__ import annotations

import itertools

import numpy as np
from skfem import Basis, LinearForm, asm
from skfem.helpers import dot

MAX_DEPTH = 5
# sub-boxes evaluated at one depth at most: a jump surface in 3D quadruples them with every
# depth (a jump line in 2D only doubles them), so the deepest splits stop here (about 0.1 GiB
# of points at 27 per box)
MAX_SUB_BOXES = 200_000
ROUGH_TOLERANCE = 1e-4


def affine_maps(mesh) -> tuple[np.ndarray, np.ndarray]:
    """v0 (d, nE) and A (d, d, nE) of x = v0 + A xi on every cell: the images of the reference
    cell's origin and unit vectors (in 2D, A = [v1 - v0, v3 - v0])."""
    d = mesh.p.shape[0]
    x = mesh._mapping().F(np.hstack([np.zeros((d, 1)), np.eye(d)]))  # (d, nE, d + 1)
    return x[:, :, 0], (x[:, :, 1:] - x[:, :, :1]).transpose(0, 2, 1)


def volumes(A: np.ndarray) -> np.ndarray:
    """|det A| (nE,) of the maps A (d, d, nE)."""
    return np.abs(np.linalg.det(A.transpose(2, 0, 1)))


def sub_rule(boxes: np.ndarray, rule) -> tuple[np.ndarray, np.ndarray]:
    """Reference points (d, n, nq) and weights (n, nq) of the rule on sub-boxes
    (corner..., size) (n, d + 1) of the reference cell."""
    X, W = rule
    d = X.shape[0]
    points = boxes[:, :d].T[:, :, None] + boxes[:, d][None, :, None] * X[:, None, :]
    return points, boxes[:, d][:, None] ** d * W[None, :]


def integrals(body_force, maps, cells, boxes, rule) -> np.ndarray:
    """int f (d, n) over sub-boxes ``boxes`` of ``cells``."""
    origin, A = maps
    xi, w = sub_rule(boxes, rule)
    x = origin[:, cells, None] + np.einsum("ijn,jnq->inq", A[:, :, cells], xi)
    return (body_force(x) * (w * volumes(A)[cells][:, None])).sum(axis=-1)


def rough_boxes(body_force, basis: Basis):
    """The rough cells, and the sub-boxes (cells, boxes) that integrate them."""
    maps, rule = affine_maps(basis.mesh), basis.quadrature
    n, d = basis.mesh.t.shape[1], basis.mesh.p.shape[0]
    children = np.array(list(itertools.product((0, 1), repeat=d)))[:, ::-1]  # x fastest
    cells, boxes = np.arange(n), np.tile([*[0.0] * d, 1.0], (n, 1))
    scale = np.abs(body_force(np.asarray(basis.global_coordinates()))).max()
    det = volumes(maps[1])
    whole = integrals(body_force, maps, cells, boxes, rule)
    kept, rough = [], np.zeros(0, dtype=int)
    for depth in range(MAX_DEPTH + 1):
        if cells.size == 0:
            break
        half = boxes[:, d:] / 2
        sub = np.concatenate([np.hstack([boxes[:, :d] + half * corner, half])
                              for corner in children], axis=1)
        sub = sub.reshape(-1, d + 1)  # the children of box i at rows 2^d i ..
        k = len(children)
        parts = integrals(body_force, maps, np.repeat(cells, k), sub, rule)
        split = (np.abs(whole - parts.reshape(d, -1, k).sum(axis=-1)).max(axis=0)
                 > ROUGH_TOLERANCE * scale * det[cells] * boxes[:, d] ** d)
        if depth == 0:
            rough = cells[split]
        elif depth == MAX_DEPTH or np.count_nonzero(split) * k > MAX_SUB_BOXES:
            split[:] = False
        if depth > 0:
            kept.append((cells[~split], boxes[~split]))
        cells = np.repeat(cells[split], k)
        boxes = sub.reshape(-1, k, d + 1)[split].reshape(-1, d + 1)
        whole = parts.reshape(d, -1, k)[:, split].reshape(d, -1)
    return rough, kept


def quad_body_load(body_force, basis: Basis) -> np.ndarray:
    """(f, v) for every function of a vector Q_p ``basis`` on parallelograms or
    parallelepipeds, the rough cells on their refined rule."""
    @LinearForm
    def form(v, w):
        return dot(body_force(w.x), v)

    F = asm(form, basis)
    rough, kept = rough_boxes(body_force, basis)
    if rough.size == 0:
        return F
    F -= asm(form, Basis(basis.mesh, basis.elem, quadrature=basis.quadrature, elements=rough))
    scalar = basis.elem.elem
    origin, A = affine_maps(basis.mesh)
    det, d = volumes(A), A.shape[0]
    for cells, boxes in kept:
        xi, w = sub_rule(boxes, basis.quadrature)
        x = origin[:, cells, None] + np.einsum("ijn,jnq->inq", A[:, :, cells], xi)
        weighted = body_force(x) * (w * det[cells][:, None])  # (d, n, nq)
        flat = xi.reshape(d, -1)
        for i in range(scalar.doflocs.shape[0]):
            phi = scalar.lbasis(flat, i)[0].reshape(xi.shape[1:])
            for c in range(d):
                F += np.bincount(basis.element_dofs[d * i + c, cells],
                                 (weighted[c] * phi).sum(axis=1), basis.N)
    return F

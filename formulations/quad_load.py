"""The load (f, v) of a body force that may jump inside a quadrilateral (docs/theory.md,
sections 9 and 15): as ``formulations.load`` does on simplices, a cell whose rule and the same
rule on its four sub-squares disagree about int f by more than ROUGH_TOLERANCE max|f| |T| is
split, up to MAX_DEPTH times, and integrated on the sub-squares that agree; elsewhere the cell
keeps its own rule. Without this the O(h) consistency error along the jump stops Q2 from
converging (measured on ``free-boundary``: the adaptive Q2 error rose from 7.5e-5 to 1.1e-4
between 7 288 and 12 752 DOFs with the cell rule alone).

The cells are parallelograms (x = v0 + A xi), so a sub-square's points and the reference
basis functions there are those of the reference square.
"""

from __future__ import annotations

import numpy as np
from skfem import Basis, LinearForm, asm
from skfem.helpers import dot

MAX_DEPTH = 5
ROUGH_TOLERANCE = 1e-4


def affine_maps(mesh) -> tuple[np.ndarray, np.ndarray]:
    """v0 (2, nE) and A = [v1 - v0, v3 - v0] (2, 2, nE) of every cell."""
    p = mesh.p[:, mesh.t]
    return p[:, 0], np.stack([p[:, 1] - p[:, 0], p[:, 3] - p[:, 0]], axis=1)


def sub_rule(squares: np.ndarray, rule) -> tuple[np.ndarray, np.ndarray]:
    """Reference points (2, n, nq) and weights (n, nq) of the rule on sub-squares
    (x0, y0, size) (n, 3) of the reference square."""
    X, W = rule
    points = squares[:, :2].T[:, :, None] + squares[:, 2][None, :, None] * X[:, None, :]
    return points, squares[:, 2][:, None] ** 2 * W[None, :]


def integrals(body_force, maps, cells, squares, rule) -> np.ndarray:
    """int f (2, n) over sub-squares ``squares`` of ``cells``."""
    origin, A = maps
    xi, w = sub_rule(squares, rule)
    x = origin[:, cells, None] + np.einsum("ijn,jnq->inq", A[:, :, cells], xi)
    det = np.abs(A[0, 0] * A[1, 1] - A[0, 1] * A[1, 0])[cells]
    return (body_force(x) * (w * det[:, None])).sum(axis=-1)


def rough_squares(body_force, basis: Basis):
    """The rough cells, and the sub-squares (cells, squares) that integrate them."""
    maps, rule = affine_maps(basis.mesh), basis.quadrature
    n = basis.mesh.t.shape[1]
    cells, squares = np.arange(n), np.tile([0.0, 0.0, 1.0], (n, 1))
    scale = np.abs(body_force(np.asarray(basis.global_coordinates()))).max()
    det = np.abs(maps[1][0, 0] * maps[1][1, 1] - maps[1][0, 1] * maps[1][1, 0])
    whole = integrals(body_force, maps, cells, squares, rule)
    kept, rough = [], np.zeros(0, dtype=int)
    for depth in range(MAX_DEPTH + 1):
        if cells.size == 0:
            break
        half = squares[:, 2:] / 2
        sub = np.concatenate([np.hstack([squares[:, :2] + half * np.array(corner), half])
                              for corner in ((0, 0), (1, 0), (0, 1), (1, 1))], axis=1)
        sub = sub.reshape(-1, 3)  # the four children of square i at rows 4i..4i+3
        parts = integrals(body_force, maps, np.repeat(cells, 4), sub, rule)
        split = (np.abs(whole - parts.reshape(2, -1, 4).sum(axis=-1)).max(axis=0)
                 > ROUGH_TOLERANCE * scale * det[cells] * squares[:, 2] ** 2)
        if depth == 0:
            rough = cells[split]
        elif depth == MAX_DEPTH:
            split[:] = False
        if depth > 0:
            kept.append((cells[~split], squares[~split]))
        cells = np.repeat(cells[split], 4)
        squares = sub.reshape(-1, 4, 3)[split].reshape(-1, 3)
        whole = parts.reshape(2, -1, 4)[:, split].reshape(2, -1)
    return rough, kept


def quad_body_load(body_force, basis: Basis) -> np.ndarray:
    """(f, v) for every function of a vector Q_p ``basis`` on parallelograms, the rough
    cells on their refined rule."""
    @LinearForm
    def form(v, w):
        return dot(body_force(w.x), v)

    F = asm(form, basis)
    rough, kept = rough_squares(body_force, basis)
    if rough.size == 0:
        return F
    F -= asm(form, Basis(basis.mesh, basis.elem, quadrature=basis.quadrature, elements=rough))
    scalar = basis.elem.elem
    origin, A = affine_maps(basis.mesh)
    det = np.abs(A[0, 0] * A[1, 1] - A[0, 1] * A[1, 0])
    for cells, squares in kept:
        xi, w = sub_rule(squares, basis.quadrature)
        x = origin[:, cells, None] + np.einsum("ijn,jnq->inq", A[:, :, cells], xi)
        weighted = body_force(x) * (w * det[cells][:, None])  # (2, n, nq)
        flat = xi.reshape(2, -1)
        for i in range(scalar.doflocs.shape[0]):
            phi = scalar.lbasis(flat, i)[0].reshape(xi.shape[1:])
            for c in range(2):
                F += np.bincount(basis.element_dofs[2 * i + c, cells],
                                 (weighted[c] * phi).sum(axis=1), basis.N)
    return F

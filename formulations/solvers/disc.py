"""Dense QPs with discs, min 1/2 lam'S lam - r'lam s.t. lam_n >= 0 and |lam_t,i| <= b_i: the
condensed Tresca problem with two tangential directions per node (3D; docs/theory.md, 17.3).

The box of the 2D problem (``box``) becomes a disc per node, whose projection is not a choice
among finitely many faces, so the primal-dual active set iteration becomes a semismooth Newton
method (Hueber, Stadler and Wohlmuth's for frictional contact, on the condensed unknowns):
with c = 1 / mean diag S and P the projection onto [0, inf)^m x discs,

    Phi(lam) = lam - P(lam - c (S lam - r)) = 0,

whose generalised Jacobian is I - D (I - c S) with D the derivative of P: 1 or 0 per normal
entry (in contact or not), per disc I where z sticks inside it and
(b / |z|) (I - z z' / |z|^2) where it slips. A full step is taken while |Phi| falls by a
factor (it does, superlinearly, near the solution), else the step is halved (Armijo on
|Phi|^2). It stops at |Phi| <= tol times the size of lam: the sets then hold exactly and the
slip directions to round-off.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import linalg

from formulations.base import STATUS_FAILED, STATUS_OK

TOLERANCE = 1e-13  # |Phi| relative to the multipliers' size: round-off of the dense solves
ARMIJO, SMALLEST_STEP = 1e-4, 2.0**-30


@dataclass(frozen=True)
class DiscResult:
    lam: np.ndarray
    iterations: int
    status: str
    reason: str
    residuals: tuple[float, ...]  # |Phi| per iteration (relative)


def project(z: np.ndarray, m: int, bound: np.ndarray) -> tuple[np.ndarray, np.ndarray,
                                                                np.ndarray]:
    """P(z), the normal entries' derivative (0 or 1) and the discs' 2 x 2 derivatives."""
    normal, pairs = z[:m], z[m:].reshape(-1, 2)
    size = np.linalg.norm(pairs, axis=1)
    inside = size <= bound
    scale = np.where(inside, 1.0, bound / np.where(size > 0, size, 1.0))
    projected = np.concatenate([np.maximum(normal, 0.0), (pairs * scale[:, None]).ravel()])
    direction = pairs / np.where(size > 0, size, 1.0)[:, None]
    outer = np.einsum("ni,nj->nij", direction, direction)
    blocks = scale[:, None, None] * (np.eye(2)[None] - np.where(inside, 0.0, 1.0)[:, None, None]
                                     * outer)
    return projected, (normal > 0).astype(float), blocks


def newton_rows(S: np.ndarray, c: float, m: int, normal: np.ndarray, blocks: np.ndarray,
                kept: np.ndarray) -> np.ndarray:
    """The rows ``kept`` of I - D (I - c S), D the block diagonal derivative of P: the normal
    entries in contact (rows c S_i) and the discs with D != 0 (both rows of each), formed from
    those rows of S alone (O(k n) for k kept rows, not a dense product)."""
    normal_rows = np.flatnonzero(kept[:m])
    nodes = np.flatnonzero(kept[m::2])
    pair_rows = m + 2 * nodes[:, None] + np.arange(2)[None, :]  # (k, 2)
    J_pairs = c * np.einsum("kij,kjn->kin", blocks[nodes], S[pair_rows])
    rest = np.eye(2)[None] - blocks[nodes]  # I - D on the disc's own entries
    for i in range(2):
        for j in range(2):
            J_pairs[np.arange(nodes.size), i, pair_rows[:, j]] += rest[:, i, j]
    return np.vstack([c * S[normal_rows], J_pairs.reshape(-1, S.shape[1])])


def newton_step(J_kept: np.ndarray, residual: np.ndarray, kept: np.ndarray) -> np.ndarray:
    """J^-1 (-residual) from J's rows ``kept`` (``newton_rows``): the other rows (D = 0 there:
    a normal entry out of contact, a node with a zero bound) are rows of the identity, so only
    the kept block is solved densely (in contact problems most points of Gamma_C are
    separated)."""
    step = -residual.copy()
    if kept.any():
        rhs = -residual[kept] - J_kept[:, ~kept] @ step[~kept]
        step[kept] = linalg.solve(J_kept[:, kept], rhs)
    return step


def disc_ssn(S: np.ndarray, r: np.ndarray, m: int, bound: np.ndarray,
             start: np.ndarray | None = None, max_iter: int = 100) -> DiscResult:
    """Semismooth Newton for the disc QP from ``start`` (default 0); ``m`` normal entries
    first, then two tangential entries per node (node-major), ``bound`` b per node."""
    c = 1.0 / max(float(np.mean(np.diag(S))), np.finfo(float).tiny) if r.size else 1.0
    lam = np.zeros(r.size) if start is None else np.asarray(start, dtype=float).copy()
    history = []

    def phi(x):
        projected, normal, blocks = project(x - c * (S @ x - r), m, bound)
        return x - projected, normal, blocks

    residual, normal, blocks = phi(lam)
    for iteration in range(1, max_iter + 1):
        size = max(np.abs(lam).max(initial=0.0), np.abs(r).max(initial=0.0) * c, 1e-300)
        history.append(float(np.linalg.norm(residual) / size))
        if history[-1] <= TOLERANCE:
            return DiscResult(lam, iteration - 1, STATUS_OK, "", tuple(history))
        kept = np.concatenate([normal > 0, np.repeat(np.abs(blocks).sum(axis=(1, 2)) > 0, 2)])
        try:
            step = newton_step(newton_rows(S, c, m, normal, blocks, kept), residual, kept)
        except linalg.LinAlgError:
            return DiscResult(lam, iteration, STATUS_FAILED, "singular Newton matrix",
                              tuple(history))
        t, merit = 1.0, residual @ residual
        while True:
            trial, trial_normal, trial_blocks = phi(lam + t * step)
            if trial @ trial <= (1 - 2 * ARMIJO * t) * merit or t < SMALLEST_STEP:
                break
            t /= 2
        lam, residual, normal, blocks = lam + t * step, trial, trial_normal, trial_blocks
    return DiscResult(lam, max_iter, STATUS_FAILED, f"|Phi| still {history[-1]:.1e} after "
                      f"{max_iter} semismooth Newton steps", tuple(history))

"""Vertex-patch saddle-point problems solved in batches (docs/theory.md, section 13.2).

Every (element, local vertex) pair contributes its element's RT mass and divergence matrices
to the patch of that vertex. A patch's unknowns are the RT DOFs of its elements that are
neither on the facets opposite its vertex (zero flux) nor prescribed (Neumann and contact
data), then per element the P_k DG multipliers of the divergence constraint; the two rows of
the stress share the matrix and are its two right-hand sides. Patches of the same system size
are stacked and solved by one batched dense LU.
"""

from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np

ZERO, FREE, FIXED = 0, 1, 2
BATCH = 2000  # patches per stacked solve: bounds the memory of the dense systems


def worker_count() -> int:
    """Threads for the patch chunks: the cores this process may use, at most OMP_NUM_THREADS
    when it is set (each chunk writes its own patches' unknowns, so the result does not depend
    on the count)."""
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    limit = os.environ.get("OMP_NUM_THREADS", "")
    return max(1, min(cores or 1, int(limit) if limit.isdigit() and int(limit) > 0 else 64))


@dataclass(frozen=True, eq=False)
class PatchLayout:
    """Where every pair's unknowns sit in its patch system.

    ``patch`` (P,) the vertex of each pair, ``status`` (P, n_rt) ZERO/FREE/FIXED, ``local``
    (P, n_rt) the position of a FREE DOF of row 0 (row 1 follows after ``n_free``),
    ``n_free`` (n_vertices,), ``rank`` (P,) the pair's position among its patch's elements,
    ``count`` (n_vertices,) elements per patch, ``key_dof`` the global DOF of each distinct
    (patch, DOF) FREE unknown and ``key_of`` (P, n_rt) the key of each FREE DOF."""

    patch: np.ndarray
    status: np.ndarray
    local: np.ndarray
    n_free: np.ndarray
    rank: np.ndarray
    count: np.ndarray
    key_dof: np.ndarray
    key_of: np.ndarray


def layout(patch: np.ndarray, dofs: np.ndarray, status: np.ndarray, holder: np.ndarray,
           n_vertices: int) -> PatchLayout:
    """``dofs`` (P, n_rt) global RT DOFs of each pair's element; ``holder`` (P, n_rt) the flat
    index (pair * n_rt + slot) of the entry that represents the same (patch, DOF) unknown (a
    DOF on a facet at the patch's vertex is held by the facet's two elements; either may
    represent it, the layout numbers the representatives patch by patch, without a sort of
    the keys)."""
    n_pairs, n_rt = status.shape
    free = status == FREE
    own = free & (holder == np.arange(n_pairs * n_rt).reshape(n_pairs, n_rt))
    order = np.argsort(patch, kind="stable")
    count = np.bincount(patch, minlength=n_vertices)
    starts = np.concatenate([[0], np.cumsum(count)[:-1]])
    rank = np.empty(n_pairs, dtype=np.int64)
    rank[order] = np.arange(n_pairs) - starts[patch[order]]
    grouped = np.flatnonzero(own[order].ravel())     # the keys, patch by patch
    key = np.full(n_pairs * n_rt, -1, dtype=np.int64)
    key[order[grouped // n_rt] * n_rt + grouped % n_rt] = np.arange(grouped.size)
    key_of = np.where(free, key[holder], -1)
    n_free = np.bincount(np.repeat(patch, n_rt)[own.ravel()], minlength=n_vertices)
    first = np.concatenate([[0], np.cumsum(n_free)[:-1]])
    key_dof = np.empty(int(n_free.sum()), dtype=np.int64)
    key_dof[key_of[own]] = dofs[own]
    return PatchLayout(patch=patch, status=status,
                       local=np.where(free, key_of - first[patch][:, None], -1),
                       n_free=n_free, rank=rank, count=count, key_dof=key_dof, key_of=key_of)


@dataclass(frozen=True, eq=False)
class PairMatrices:
    """Per element (pair p belongs to element p // 3): ``mass`` (n_el, n_rt, n_rt) and
    ``divergence`` (n_el, n_dg, n_rt); per pair: ``rhs`` (P, n_rt, 2), ``data`` (P, n_dg, 2)
    and the prescribed values ``fixed`` (P, n_rt, 2) (zero where not FIXED)."""

    mass: np.ndarray
    divergence: np.ndarray
    rhs: np.ndarray
    data: np.ndarray
    fixed: np.ndarray


def solve_patches(lay: PatchLayout, pairs: PairMatrices, clamped: np.ndarray) -> np.ndarray:
    """The FREE unknowns (n_keys, 2) of every patch problem

        [M  B'] [x]   [rhs ]
        [B  0 ] [y] = [data]   (minus the prescribed DOFs' share),

    one system per patch with the two rows of the stress as right-hand sides. Off Gamma_D
    (``clamped`` False) the first multiplier is dropped: the data balance, so its equation
    follows from the others (docs/theory.md, 13.2)."""
    rhs, data = pairs.rhs.copy(), pairs.data.copy()
    touched = np.flatnonzero((lay.status == FIXED).any(axis=1))  # pairs on Gamma_N, Gamma_C
    fixed, element = pairs.fixed[touched], touched // 3
    rhs[touched] -= np.matmul(pairs.mass[element], fixed)
    data[touched] -= np.matmul(pairs.divergence[element], fixed)
    size = lay.n_free + lay.count * pairs.divergence.shape[1]
    out = np.zeros((lay.key_dof.size, 2))
    jobs = [(chunk, int(n)) for n in np.unique(size)
            for chunk in np.array_split(np.flatnonzero(size == n),
                                        max(1, -(-(size == n).sum() // BATCH)))]
    with ThreadPoolExecutor(max_workers=worker_count()) as pool:
        list(pool.map(lambda job: _solve_chunk(lay, job[0], job[1], pairs,
                                               (rhs, data), clamped, out), jobs))
    return out


def _solve_chunk(lay, chunk, n, pairs, right, clamped, out) -> None:
    rhs, data = right
    position = np.full(lay.n_free.size, -1)
    position[chunk] = np.arange(chunk.size)
    sel = np.flatnonzero(position[lay.patch] >= 0)
    g = position[lay.patch[sel]]
    nf = lay.n_free[lay.patch[sel]]
    n_dg = pairs.divergence.shape[1]
    free = lay.status[sel] == FREE
    loc = lay.local[sel]
    div_at = nf + lay.rank[sel] * n_dg
    entries = _Entries(chunk.size, n, 2)
    element = sel // 3
    entries.matrix(g, loc[:, :, None], loc[:, None, :], pairs.mass[element],
                   free[:, :, None] & free[:, None, :])
    _constraint(entries, g, div_at, loc, free, pairs.divergence[element])
    rows = div_at[:, None] + np.arange(n_dg)
    for r in (0, 1):
        entries.vector(g, loc, rhs[sel][..., r], free, r)
        entries.vector(g, rows, data[sel][..., r], np.ones(rows.shape, bool), r)
    A, b = entries.assembled()
    neumann = (lay.rank[sel] == 0) & ~clamped[lay.patch[sel]]
    k, d = g[neumann], div_at[neumann]
    A[k, d, :] = 0.0
    A[k, :, d] = 0.0
    A[k, d, d] = 1.0
    b[k, d] = 0.0
    x = np.linalg.solve(A, b)
    gf = np.broadcast_to(g[:, None], free.shape)[free]
    out[lay.key_of[sel][free]] = x[gf, loc[free]]


class _Entries:
    """Accumulates (system, row, column, value) entries of stacked dense systems and sums
    them with one ``bincount`` (duplicates add up)."""

    def __init__(self, count: int, n: int, columns: int):
        self.count, self.n, self.columns = count, n, columns
        self.a_index, self.a_value, self.b_index, self.b_value = [], [], [], []

    def matrix(self, g, rows, cols, values, mask) -> None:
        shape = mask.shape
        flat = (np.broadcast_to(g[:, None, None], shape) * self.n
                + np.broadcast_to(rows, shape)) * self.n + np.broadcast_to(cols, shape)
        self.a_index.append(flat[mask])
        self.a_value.append(values[mask])

    def vector(self, g, rows, values, mask, column) -> None:
        flat = (np.broadcast_to(g[:, None], mask.shape) * self.n + rows) * self.columns + column
        self.b_index.append(flat[mask])
        self.b_value.append(values[mask])

    def assembled(self) -> tuple[np.ndarray, np.ndarray]:
        size = self.count * self.n
        A = np.bincount(np.concatenate(self.a_index), np.concatenate(self.a_value),
                        minlength=size * self.n).reshape(self.count, self.n, self.n)
        b = np.bincount(np.concatenate(self.b_index), np.concatenate(self.b_value),
                        minlength=size * self.columns).reshape(self.count, self.n, self.columns)
        return A, b


def _constraint(entries: _Entries, g, start, loc, free, block) -> None:
    """Constraint rows start + i of one element against its FREE DOFs, and the transpose."""
    mask = np.broadcast_to(free[:, None, :], block.shape)
    rows = (start[:, None] + np.arange(block.shape[1]))[:, :, None]
    entries.matrix(g, rows, loc[:, None, :], block, mask)
    entries.matrix(g, loc[:, None, :], rows, block, mask)

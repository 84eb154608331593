"""Vertex-patch saddle-point problems solved in batches (docs/theory.md, section 13.2).

Every (element, local vertex) pair contributes its element's RT mass, divergence and symmetry
matrices to the patch of that vertex. A patch's unknowns are, for both rows of the stress, the
RT DOFs of its elements that are neither on the facets opposite its vertex (zero flux) nor
prescribed (Neumann and contact data); then per element the P_k DG multipliers of the two
divergence constraints and the P_(k-1) multipliers of the weak symmetry constraint. Patches of
the same system size are stacked and solved by one batched dense LU.
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
    """Per element (pair p belongs to element p // 3): ``mass`` (n_el, n_rt, n_rt),
    ``divergence`` (n_el, n_dg, n_rt), ``symmetry`` (n_el, n_sym, 2, n_rt) (row r's share of
    (sigma_12 - sigma_21, gamma)); per pair: ``rhs`` (P, n_rt, 2), ``data`` (P, n_dg, 2),
    ``skew`` (P, n_sym) and the prescribed values ``fixed`` (P, n_rt, 2) (zero where not
    FIXED)."""

    mass: np.ndarray
    divergence: np.ndarray
    symmetry: np.ndarray
    rhs: np.ndarray
    data: np.ndarray
    skew: np.ndarray
    fixed: np.ndarray


def solve_patches(lay: PatchLayout, pairs: PairMatrices, clamped: np.ndarray) -> np.ndarray:
    """The FREE unknowns (n_keys, 2) of every patch problem

        [M  0  B' 0  S0'] [x0]   [rhs0 ]
        [0  M  0  B' S1'] [x1]   [rhs1 ]
        [B  0  0  0  0  ] [y0] = [data0]   (minus the prescribed DOFs' share)
        [0  B  0  0  0  ] [y1]   [data1]
        [S0 S1 0  0  0  ] [z ]   [skew ]

    Without symmetry constraints (n_sym = 0) the rows decouple: one system per patch with the
    two rows as right-hand sides. Off Gamma_D (``clamped`` False) the first multiplier of each
    constraint is dropped: the data balance, so its equation follows from the others
    (docs/theory.md, 13.2)."""
    rhs, data, skew = pairs.rhs.copy(), pairs.data.copy(), pairs.skew.copy()
    touched = np.flatnonzero((lay.status == FIXED).any(axis=1))  # pairs on Gamma_N, Gamma_C
    fixed, element = pairs.fixed[touched], touched // 3
    rhs[touched] -= np.matmul(pairs.mass[element], fixed)
    data[touched] -= np.matmul(pairs.divergence[element], fixed)
    skew[touched] -= np.einsum("pgrl,plr->pg", pairs.symmetry[element], fixed)
    n_dg, n_sym = pairs.divergence.shape[1], pairs.symmetry.shape[1]
    blocks = 2 if n_sym else 1
    size = blocks * lay.n_free + lay.count * (blocks * n_dg + n_sym)
    out = np.zeros((lay.key_dof.size, 2))
    jobs = [(chunk, int(n)) for n in np.unique(size)
            for chunk in np.array_split(np.flatnonzero(size == n),
                                        max(1, -(-(size == n).sum() // BATCH)))]
    with ThreadPoolExecutor(max_workers=worker_count()) as pool:
        list(pool.map(lambda job: _solve_chunk(lay, job[0], job[1], pairs,
                                               (rhs, data, skew), clamped, out), jobs))
    return out


def _solve_chunk(lay, chunk, n, pairs, right, clamped, out) -> None:
    rhs, data, skew = right
    position = np.full(lay.n_free.size, -1)
    position[chunk] = np.arange(chunk.size)
    sel = np.flatnonzero(position[lay.patch] >= 0)
    g = position[lay.patch[sel]]
    nf, count = lay.n_free[lay.patch[sel]], lay.count[lay.patch[sel]]
    n_dg, n_sym = pairs.divergence.shape[1], pairs.symmetry.shape[1]
    blocks, columns = (2, 1) if n_sym else (1, 2)
    free = lay.status[sel] == FREE
    loc = [lay.local[sel] + r * nf[:, None] for r in range(blocks)]
    div_at = [blocks * nf + r * count * n_dg + lay.rank[sel] * n_dg for r in range(blocks)]
    sym_at = blocks * nf + blocks * count * n_dg + lay.rank[sel] * n_sym
    entries = _Entries(chunk.size, n, columns)
    both = free[:, :, None] & free[:, None, :]
    element = sel // 3
    for r in range(blocks):
        entries.matrix(g, loc[r][:, :, None], loc[r][:, None, :], pairs.mass[element], both)
        _constraint(entries, g, div_at[r], loc[r], free, pairs.divergence[element])
        if n_sym:
            _constraint(entries, g, sym_at, loc[r], free, pairs.symmetry[element][:, :, r])
    rows = [div_at[r][:, None] + np.arange(n_dg) for r in range(blocks)]
    for r in (0, 1):
        block, column = (r, 0) if n_sym else (0, r)
        entries.vector(g, loc[block], rhs[sel][..., r], free, column)
        entries.vector(g, rows[block], data[sel][..., r], np.ones(rows[block].shape, bool),
                       column)
    if n_sym:
        sym_rows = sym_at[:, None] + np.arange(n_sym)
        entries.vector(g, sym_rows, skew[sel], np.ones(sym_rows.shape, bool), 0)
    A, b = entries.assembled()
    neumann = (lay.rank[sel] == 0) & ~clamped[lay.patch[sel]]
    for dropped in div_at + ([sym_at] if n_sym else []):
        k, d = g[neumann], dropped[neumann]
        A[k, d, :] = 0.0
        A[k, :, d] = 0.0
        A[k, d, d] = 1.0
        b[k, d] = 0.0
    x = np.linalg.solve(A, b)
    keys = lay.key_of[sel][free]
    gf = np.broadcast_to(g[:, None], free.shape)[free]
    out[keys] = (np.stack([x[gf, loc[0][free], 0], x[gf, loc[1][free], 0]], axis=1) if n_sym
                 else x[gf, loc[0][free]])


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

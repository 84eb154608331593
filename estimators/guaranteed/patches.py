"""Vertex-patch saddle-point problems solved in batches (docs/theory.md, section 13.2).

Every (element, local vertex) pair contributes its element's RT mass and divergence matrices
to the patch of that vertex. A patch's unknowns are the RT DOFs of its elements that are
neither on the facets opposite its vertex (zero flux) nor prescribed (Neumann and contact
data), then per element the P_k DG multipliers of the divergence constraint; the rows of
the stress (two on triangles, three on tetrahedra) share the matrix and are its right-hand
sides. Patches of the same system size are stacked; a chunk of them is solved by one batched
dense LU, or, where patches share their system (``estimators.guaranteed.patch_classes``), by the
inverses of the chunk's distinct systems (on tetrahedra after ``estimators.
patch_condensation`` has eliminated the element-interior unknowns)."""

from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np

from estimators.guaranteed.patch_classes import Classes, patch_owners

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
    (patch, DOF) FREE unknown, and ``by_patch`` the pairs patch by patch, each patch's in
    rank order, from ``start`` (n_vertices,); ``first`` (n_vertices,) the key of each patch's
    first unknown (a patch's keys are consecutive)."""

    patch: np.ndarray
    status: np.ndarray
    local: np.ndarray
    n_free: np.ndarray
    rank: np.ndarray
    count: np.ndarray
    key_dof: np.ndarray
    by_patch: np.ndarray
    start: np.ndarray
    first: np.ndarray

    def pairs_of(self, patches: np.ndarray) -> np.ndarray:
        """The pairs of ``patches``, patch by patch in that order."""
        count = self.count[patches]
        offset = np.arange(count.sum()) - np.repeat(np.cumsum(count) - count, count)
        return self.by_patch[np.repeat(self.start[patches], count) + offset]


def index_type(size: int) -> type:
    """int32 for indices below 2^31 (half the memory traffic of the (pairs, n_rt) arrays)."""
    return np.int32 if size < 2**31 else np.int64


def layout(patch: np.ndarray, dofs: np.ndarray, status: np.ndarray, holder: np.ndarray,
           n_vertices: int) -> PatchLayout:
    """``dofs`` (P, n_rt) global RT DOFs of each pair's element; ``holder`` (P, n_rt) the flat
    index (pair * n_rt + slot) of the entry that represents the same (patch, DOF) unknown (a
    DOF on a facet at the patch's vertex is held by the facet's two elements; either may
    represent it, the layout numbers the representatives patch by patch, without a sort of
    the keys). A FREE entry's holder is FREE: only FREE entries' keys are read."""
    n_pairs, n_rt = status.shape
    itype = index_type(n_pairs * n_rt)
    free = status == FREE
    own = free & (holder == np.arange(n_pairs * n_rt, dtype=itype).reshape(n_pairs, n_rt))
    order = np.argsort(patch, kind="stable")
    count = np.bincount(patch, minlength=n_vertices)
    starts = np.concatenate([[0], np.cumsum(count)[:-1]])
    rank = np.empty(n_pairs, dtype=np.int64)
    rank[order] = np.arange(n_pairs) - starts[patch[order]]
    grouped = np.flatnonzero(own[order].ravel())     # the keys, patch by patch
    key = np.zeros(n_pairs * n_rt, dtype=itype)
    key[order[grouped // n_rt] * n_rt + grouped % n_rt] = np.arange(grouped.size, dtype=itype)
    key_of = key[holder]   # read at FREE entries only
    n_free = np.bincount(np.repeat(patch, n_rt)[own.ravel()], minlength=n_vertices)
    first = np.concatenate([[0], np.cumsum(n_free)[:-1]])
    key_dof = np.empty(int(n_free.sum()), dtype=np.int64)
    key_dof[key_of[own]] = dofs[own]
    local = key_of - first[patch].astype(itype)[:, None]
    local[~free] = -1
    return PatchLayout(patch=patch, status=status, local=local, n_free=n_free, rank=rank,
                       count=count, key_dof=key_dof, by_patch=order,
                       start=starts, first=first)


@dataclass(frozen=True, eq=False)
class PairMatrices:
    """Per class of elements with equal matrices (``estimators.guaranteed.patch_classes``): ``mass``
    (n_classes, n_rt, n_rt) and ``divergence`` (n_classes, n_dg, n_rt), and ``element_class``
    (n_el,) the class of each element (pair p belongs to element p // corners, ``corners`` = 3
    on triangles, 4 on tetrahedra); per pair, with one column per row of the stress (d):
    ``rhs`` (P, n_rt, d), ``data`` (P, n_dg, d) and the prescribed values ``fixed`` (P, n_rt, d)
    (zero where not FIXED)."""

    mass: np.ndarray
    divergence: np.ndarray
    element_class: np.ndarray
    rhs: np.ndarray
    data: np.ndarray
    fixed: np.ndarray
    corners: int

    def class_of(self, pairs: np.ndarray) -> np.ndarray:
        """The class of the element of each pair."""
        return self.element_class[pairs // self.corners]


def solve_patches(lay: PatchLayout, pairs: PairMatrices, clamped: np.ndarray) -> np.ndarray:
    """The FREE unknowns (n_keys, d) of every patch problem

        [M  B'] [x]   [rhs ]
        [B  0 ] [y] = [data]

    (``pairs``' rhs and data already less the prescribed DOFs' share: ``moved_prescribed``),
    one system per patch with the rows of the stress as right-hand sides. Off Gamma_D
    (``clamped`` False) the first multiplier is dropped: the data balance, so its equation
    follows from the others (docs/theory.md, 13.2). Patches with equal systems
    (``estimators.guaranteed.patch_classes``) share one factorisation."""
    size = lay.n_free + lay.count * pairs.divergence.shape[1]
    owner = patch_owners(lay, pairs, clamped, size)
    out = np.zeros((lay.key_dof.size, pairs.rhs.shape[-1]))
    jobs = []
    for n in np.unique(size):
        members = np.flatnonzero(size == n)
        members = members[np.argsort(owner[members], kind="stable")]   # classes together
        jobs += [(chunk, int(n)) for chunk in np.array_split(members, -(-members.size // BATCH))]
    with ThreadPoolExecutor(max_workers=worker_count()) as pool:
        list(pool.map(lambda job: _solve_chunk(lay, job[0], job[1], pairs, clamped, owner, out),
                      jobs))
    return out


def moved_prescribed(status: np.ndarray, pairs: PairMatrices) -> tuple[np.ndarray, np.ndarray]:
    """The pairs' ``rhs`` and ``data`` less the prescribed DOFs' share (status FIXED)."""
    rhs, data = pairs.rhs.copy(), pairs.data.copy()
    touched = np.flatnonzero((status == FIXED).any(axis=1))  # pairs on Gamma_N, Gamma_C
    fixed, element = pairs.fixed[touched], pairs.class_of(touched)
    rhs[touched] -= np.matmul(pairs.mass[element], fixed)
    data[touched] -= np.matmul(pairs.divergence[element], fixed)
    return rhs, data


def _solve_chunk(lay, chunk, n, pairs, clamped, owner, out) -> None:
    """The patches ``chunk`` (of system size n): one system per class in the chunk, then
    either one LU per patch or, where classes repeat, the classes' inverses."""
    classes = Classes.of_owners(owner[chunk])
    A = _systems(lay, classes.first, n, pairs, clamped)
    view = _ChunkPairs.of(lay, chunk, n, pairs.divergence.shape[1])
    b = _right_hand_sides(lay, view, n, pairs, clamped)
    if 4 * classes.first.size > chunk.size:     # few repeats: an LU per patch is cheaper
        x = np.linalg.solve(A[classes.of], b)
    else:
        x = np.empty_like(b)
        x[classes.order] = classes.products(np.linalg.inv(A), b[classes.order])
    rows = np.arange(n)
    unknown = rows[None, :] < lay.n_free[chunk][:, None]  # a patch's keys are consecutive
    out[(lay.first[chunk][:, None] + rows)[unknown]] = x[unknown]


@dataclass(frozen=True, eq=False)
class _ChunkPairs:
    """The pairs ``sel`` of a chunk of ``size`` patches: their patch's position ``g`` in the
    chunk, FREE mask, local positions and first multiplier row ``div_at``."""

    size: int
    sel: np.ndarray
    g: np.ndarray
    free: np.ndarray
    loc: np.ndarray
    div_at: np.ndarray

    @staticmethod
    def of(lay: PatchLayout, chunk: np.ndarray, n: int, n_dg: int) -> _ChunkPairs:
        sel = lay.pairs_of(chunk)
        g = np.repeat(np.arange(chunk.size), lay.count[chunk])
        return _ChunkPairs(size=chunk.size, sel=sel, g=g,
                           free=lay.status[sel] == FREE, loc=lay.local[sel],
                           div_at=lay.n_free[lay.patch[sel]] + lay.rank[sel] * n_dg)

    def dropped(self, lay: PatchLayout, clamped: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The patch positions and rows of the dropped multipliers (off Gamma_D)."""
        neumann = (lay.rank[self.sel] == 0) & ~clamped[lay.patch[self.sel]]
        return self.g[neumann], self.div_at[neumann]


def _systems(lay, chunk, n, pairs, clamped) -> np.ndarray:
    """The matrices (len(chunk), n, n) of the patches ``chunk``."""
    view = _ChunkPairs.of(lay, chunk, n, pairs.divergence.shape[1])
    entries = _Entries(chunk.size, n)
    element = pairs.class_of(view.sel)
    free = view.free
    entries.matrix(view.g, view.loc[:, :, None], view.loc[:, None, :], pairs.mass[element],
                   free[:, :, None] & free[:, None, :])
    _constraint(entries, view.g, view.div_at, view.loc, free, pairs.divergence[element])
    A = entries.assembled_matrix()
    k, d = view.dropped(lay, clamped)
    A[k, d, :] = 0.0
    A[k, :, d] = 0.0
    A[k, d, d] = 1.0
    return A


def _right_hand_sides(lay, view, n, pairs, clamped) -> np.ndarray:
    """The right-hand sides (patches, n, d) of the chunk ``view``: each pair's multiplier
    rows are its own; a FREE unknown on a facet is shared by the facet's two pairs."""
    rhs, data = pairs.rhs, pairs.data
    d = rhs.shape[-1]
    b = np.zeros((view.size, n, d))
    rows = view.div_at[:, None] + np.arange(pairs.divergence.shape[1])
    b[view.g[:, None], rows] = data[view.sel]
    at = (view.g[:, None] * n + view.loc)[view.free]
    shared = np.bincount(np.concatenate([d * at + r for r in range(d)]),
                         rhs[view.sel][view.free].T.ravel(), minlength=b.size)
    b += shared.reshape(b.shape)
    k, d = view.dropped(lay, clamped)
    b[k, d] = 0.0
    return b


class _Entries:
    """Accumulates (system, row, column, value) entries of stacked dense matrices and sums
    them with one ``bincount`` (duplicates add up)."""

    def __init__(self, count: int, n: int):
        self.count, self.n = count, n
        self.a_index, self.a_value = [], []

    def matrix(self, g, rows, cols, values, mask) -> None:
        shape = mask.shape
        flat = (np.broadcast_to(g[:, None, None], shape) * self.n
                + np.broadcast_to(rows, shape)) * self.n + np.broadcast_to(cols, shape)
        self.a_index.append(flat[mask])
        self.a_value.append(values[mask])

    def assembled_matrix(self) -> np.ndarray:
        return np.bincount(np.concatenate(self.a_index), np.concatenate(self.a_value),
                           minlength=self.count * self.n**2).reshape(self.count, self.n, self.n)


def _constraint(entries: _Entries, g, start, loc, free, block) -> None:
    """Constraint rows start + i of one element against its FREE DOFs, and the transpose."""
    mask = np.broadcast_to(free[:, None, :], block.shape)
    rows = (start[:, None] + np.arange(block.shape[1]))[:, :, None]
    entries.matrix(g, rows, loc[:, None, :], block, mask)
    entries.matrix(g, loc[:, None, :], rows, block, mask)

"""Vertex patches whose saddle-point systems are equal (docs/theory.md, section 13.2, "Patch
classes").

With the Piola map the RT_k mass matrix of a triangle depends only on its shape up to
translation, rotation and scale (J'J / |det J|) and the orientations of its facets, and the
divergence matrix only on those orientations. A patch system is assembled from its elements'
matrices at positions fixed by the patch layout, so two patches whose elements have equal
matrices, in the same order and at the same positions, have the same system; only the
right-hand sides differ. Meshes refined from a few starting triangles have few such classes
(143 for the 261 121 interior patches of `paper` refined seven times), so each class's system
is factorised once.

Grouping is by hashes; every member is then compared with its class's representative, and a
member that differs (a hash collision, or matrices that differ by more than round-off) forms a
class of its own, so a class never holds two different systems.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from estimators.guaranteed.rt_reference import facet_dof_count, orientations

HASH_SEED = 20261202  # the random weights of ``patch_owners``' hash (any: collisions are checked)

ELEMENT_TOLERANCE = 1e-12  # relative: equal up to the round-off of computing J from the mesh
_SEED = 20261129


def element_classes(mesh, k: int) -> np.ndarray:
    """For every element the index of an element with the same RT_k mass and divergence
    matrices: the same J'J / |det J| and facet orientations, all that
    ``estimators.guaranteed.rt_reference.element_matrices`` makes them of."""
    mapping, d = mesh.mapping(), mesh.dim()
    metric = np.einsum("ice,ide->ecd", mapping.A, mapping.A).reshape(-1, d * d)
    per_facet = facet_dof_count(k, d)
    signs = orientations(mesh, (d + 1) * per_facet, k)[:, ::per_facet]
    return equal_rows([metric / np.abs(mapping.detA)[:, None], signs])


def equal_rows(arrays: list[np.ndarray]) -> np.ndarray:
    """For every index i of the first axis the first index whose entries in all ``arrays``
    equal those of i, in each array to ``ELEMENT_TOLERANCE`` of its row's largest entry."""
    n_el = arrays[0].shape[0]
    flat = [a.reshape(n_el, -1) for a in arrays]
    scale = max(max(f.max(initial=0.0), -f.min(initial=0.0)) for f in flat) or 1.0
    owner = _first_with_hash(element_hash(flat, scale))
    differs = np.zeros(n_el, dtype=bool)
    for chunk in np.array_split(np.arange(n_el), max(1, n_el // 100_000)):
        for f in flat:
            theirs = f[owner[chunk]]
            differs[chunk] |= (np.abs(f[chunk] - theirs).max(axis=1)
                               > ELEMENT_TOLERANCE * np.abs(theirs).max(axis=1))
    owner[differs] = np.flatnonzero(differs)
    return owner


@dataclass(frozen=True, eq=False)
class Classes:
    """Elements grouped by equal matrices: ``of`` (n_el,) the class of each, ``first``
    (n_classes,) an element of each class, ``order`` the elements class by class and ``bounds``
    (n_classes + 1,) where each class starts in ``order``."""

    of: np.ndarray
    first: np.ndarray
    order: np.ndarray
    bounds: np.ndarray

    @staticmethod
    def of_owners(owner: np.ndarray) -> Classes:
        first, of = np.unique(owner, return_inverse=True)
        of = of.ravel()
        order = np.argsort(of, kind="stable")
        return Classes(of=of, first=first, order=order,
                       bounds=np.searchsorted(of[order], np.arange(first.size + 1)))

    def products(self, matrices: np.ndarray, local: np.ndarray) -> np.ndarray:
        """matrices[of[e]] @ local[e] for the class matrices (n_classes, m, n) and ``local``
        (n_el, n, ...) given class by class (element ``order[i]`` in row i): one matrix
        product per class where classes repeat, else one per element."""
        if 8 * self.first.size > self.of.size:
            return np.einsum("eij,ej...->ei...", matrices[self.of[self.order]], local)
        out = np.empty(local.shape[:1] + matrices.shape[1:2] + local.shape[2:],
                       dtype=np.result_type(matrices, local))
        for c, (lo, hi) in enumerate(zip(self.bounds[:-1], self.bounds[1:], strict=True)):
            out[lo:hi] = np.einsum("ij,ej...->ei...", matrices[c], local[lo:hi], optimize=True)
        return out


def patch_classes(keys: np.ndarray) -> np.ndarray:
    """For every row of the integer ``keys`` (m, L) the index of the first row equal to it."""
    owner = _first_with_hash(key_hash(keys))
    differs = np.flatnonzero((keys != keys[owner]).any(axis=1))
    owner[differs] = differs
    return owner


def element_hash(flat: list[np.ndarray], scale: float) -> np.ndarray:
    """A random projection of each element's matrices, rounded to 7 digits of ``scale``."""
    rng = np.random.default_rng(_SEED)
    return np.round(sum(f @ rng.standard_normal(f.shape[1]) for f in flat) / scale * 1e7)


def key_hash(keys: np.ndarray) -> np.ndarray:
    """A random integer combination of each row (wrapping on overflow)."""
    weights = np.random.default_rng(_SEED).integers(1, 2**61, size=keys.shape[1])
    with np.errstate(over="ignore"):
        return (keys.astype(np.int64) * weights).sum(axis=1)


def _first_with_hash(h: np.ndarray) -> np.ndarray:
    _, first, inverse = np.unique(h, return_index=True, return_inverse=True)
    return first[inverse.ravel()]


def patch_owners(lay, pairs, clamped: np.ndarray, size: np.ndarray) -> np.ndarray:
    """For every patch of ``lay`` (an ``estimators.guaranteed.patches.PatchLayout``, its element
    matrices ``pairs``, ``PairMatrices``; ``size`` the system sizes) the first patch with the
    same system: equal size, element count and
    clamping, and per element rank the same element matrices (the same ``element_class``)
    at the same positions. Grouped by a hash of these, pair by pair, then every patch is
    compared with its group's first; one that differs is a class of its own."""
    n_rt = lay.local.shape[1]
    rng = np.random.default_rng(HASH_SEED)
    weights = rng.integers(1, 2**61, size=n_rt + 1)
    by_rank = rng.integers(1, 2**61, size=int(lay.count.max(initial=1)))
    ordered = lay.by_patch
    with np.errstate(over="ignore"):
        pair_hash = ((pairs.class_of(ordered) * weights[0]
                      + lay.local[ordered].astype(np.int64) @ weights[1:])
                     * by_rank[lay.rank[ordered]])
        patch_hash = np.zeros(lay.count.size, dtype=np.int64)
        filled = lay.count > 0
        patch_hash[filled] = np.add.reduceat(pair_hash, lay.start[filled])
    keys = np.stack([size, lay.count, clamped.astype(np.int64), patch_hash], axis=1)
    owner = patch_classes(keys)
    return np.where(_same_pairs(lay, pairs, owner), owner, np.arange(owner.size))


def _same_pairs(lay, pairs, owner: np.ndarray) -> np.ndarray:
    """Whether each patch's pairs equal its ``owner``'s, rank by rank: element class and
    local positions (the hash of ``patch_owners`` grouped them; this rules out collisions)."""
    other = np.flatnonzero(owner != np.arange(owner.size))
    same = np.ones(owner.size, dtype=bool)
    if other.size == 0:
        return same
    mine, theirs = lay.pairs_of(other), lay.pairs_of(owner[other])   # equal counts: in the key
    differs = ((pairs.class_of(mine) != pairs.class_of(theirs))
               | (lay.local[mine] != lay.local[theirs]).any(axis=1))
    patch = np.repeat(np.arange(other.size), lay.count[other])
    same[other] = np.bincount(patch, differs, minlength=other.size) == 0
    return same

"""Sparse direct back-ends: one factorisation of K that also yields the Schur complement of K on
the contact DOFs, the only part of K the contact iteration needs.

With the DOFs split into interior I and contact C (those B touches, on one boundary line),

    S_C = K_CC - K_CI K_II^-1 K_IC,    (K^-1)_CC = S_C^-1,

so B K^-1 B' = B_C S_C^-1 B_C' is a small dense matrix. Two back-ends compute it:

* ``cholmod`` (optional: scikit-sparse, which needs SuiteSparse's headers at install time, e.g.
  Debian's libsuitesparse-dev; with an optimised BLAS such as libopenblas0-pthread). K is ordered
  with AMD on the interior DOFs followed by the contact DOFs, and factorised once, K = L L'. The
  trailing block of L is the Cholesky factor of S_C: no extra solves at all.
* ``splu`` (always available: scipy's SuperLU). Forming S_C would take |C| solves (measured:
  minutes per level at 5e5 DOFs on adaptive meshes, where |C| is in the thousands), so with splu
  the active-set solver factorises the augmented saddle-point system once per iteration instead
  (``augmented``); nested iteration keeps that to one to three factorisations per level.

Measured on the paper scene (2 cores, OpenBLAS; ``python -m bench scaling``), cholmod wins at every
size, so it is the default whenever it imports; ``splu`` is the pure-scipy fallback.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy import linalg, sparse
from scipy.sparse.linalg import splu

try:  # optional dependency
    from sksparse import cholmod
except ImportError:  # pragma: no cover - depends on the installation
    cholmod = None

BACKENDS = ("cholmod", "splu")


class BackendError(ValueError):
    """An unknown or unavailable back-end was asked for."""


def available_backends() -> tuple[str, ...]:
    return tuple(b for b in BACKENDS if b != "cholmod" or cholmod is not None)


def default_backend() -> str:
    return available_backends()[0]


def check_backend(backend: str | None) -> str:
    """The back-end to use for ``backend`` (None means the default), or a clear error."""
    if backend is None:
        return default_backend()
    if backend not in BACKENDS:
        raise BackendError(f"backend={backend!r} is not one of {', '.join(BACKENDS)}")
    if backend not in available_backends():
        raise BackendError(f"backend={backend!r} is not available: install scikit-sparse "
                           "(needs SuiteSparse headers, e.g. apt-get install libsuitesparse-dev)")
    return backend


@dataclass(frozen=True, eq=False)
class CondensedFactor:
    """A factorisation of K (``solve``) and the lower Cholesky factor of S_C on ``contact``."""

    backend: str
    contact: np.ndarray
    solve: Callable[[np.ndarray], np.ndarray]
    schur_cholesky: np.ndarray
    phases: tuple[tuple[str, float], ...] = ()  # (phase, seconds) of the factorisation

    def condensed(self, B: sparse.spmatrix) -> np.ndarray:
        """B K^-1 B' for a B whose columns vanish outside ``contact`` (dense, m x m)."""
        W = linalg.solve_triangular(self.schur_cholesky, B[:, self.contact].T.toarray(),
                                    lower=True, check_finite=False)
        return W.T @ W


def factorise(K: sparse.spmatrix, backend: str | None = None) -> Callable[[np.ndarray], np.ndarray]:
    """A plain factorisation of K: the linear-solve floor every contact solve is measured
    against (same back-end, same ordering as ``factorise_condensed`` uses on the interior)."""
    backend = check_backend(backend)
    K = sparse.csc_matrix(K)
    if backend == "cholmod":
        return cholmod.cholesky(K, ordering_method="amd")
    return splu(K).solve


def factorise_condensed(K: sparse.spmatrix, contact: np.ndarray,
                        backend: str | None = None) -> CondensedFactor:
    backend = check_backend(backend)
    K = sparse.csc_matrix(K)
    n = K.shape[0]
    contact = np.unique(np.asarray(contact, dtype=np.int64))
    interior = np.setdiff1d(np.arange(n), contact)
    if backend != "cholmod":
        raise BackendError(f"backend={backend!r} gives no cheap Schur complement; only "
                           "cholmod does (splu runs the augmented iteration instead)")
    return _cholmod_condensed(K, interior, contact)


def _cholmod_condensed(K, interior, contact) -> CondensedFactor:
    n, nc = K.shape[0], contact.size
    clock = time.perf_counter()
    order = cholmod.analyze(K[interior][:, interior], ordering_method="amd").P()
    perm = np.concatenate([interior[order], contact])
    permuted = K[perm][:, perm].tocsc()
    phases = [("order", time.perf_counter() - clock)]
    clock = time.perf_counter()
    factor = cholmod.cholesky(permuted, ordering_method="natural")
    phases.append(("factorise", time.perf_counter() - clock))
    if not np.array_equal(factor.P(), np.arange(n)):  # the trailing block must stay C
        raise RuntimeError("CHOLMOD reordered a factorisation asked for in natural order")
    clock = time.perf_counter()
    L_CC = factor.L()[n - nc:, n - nc:].toarray()
    phases.append(("schur block", time.perf_counter() - clock))
    inverse = np.empty(n, dtype=np.int64)
    inverse[perm] = np.arange(n)

    def solve(b):
        return factor(np.asarray(b)[perm])[inverse]

    return CondensedFactor("cholmod", contact, solve, np.tril(L_CC), tuple(phases))

"""Sparse direct back-ends: one factorisation of K that also yields the Schur complement of K on
the contact DOFs, the only part of K the contact iteration needs (docs/theory.md, section 11).

With the DOFs split into interior I and contact C (those B touches, on one boundary line),

    S_C = K_CC - K_CI K_II^-1 K_IC,    (K^-1)_CC = S_C^-1,

so B K^-1 B' = B_C S_C^-1 B_C' is a small dense matrix. A back-end is one module here that calls
``register_backend``; its ``rank`` orders the preference (the default is the first available):

* ``pardiso`` (``pardiso.py``; Intel MKL PARDISO through pypardiso's library, installed by
  ``pip install .`` on x86_64): S_C straight from PARDISO's partial factorisation;
* ``cholmod`` (``cholmod.py``; optional scikit-sparse, needs SuiteSparse's headers): S_C as the
  trailing block of the Cholesky factor with C ordered last;
* ``splu`` (``splu.py``; scipy's SuperLU, always there): no cheap S_C, so the active-set solver
  factorises the augmented saddle-point system once per iteration (``augmented``);
* ``amg`` (``amg.py``; PyAMG): no factorisation at all, Krylov iterations preconditioned by
  smoothed-aggregation multigrid; the active-set solver runs its projected iteration
  (``projected``). Never the default: chosen by name, or by the route choice when a level
  does not fit a direct factorisation (``bench.sequence.memory``).

The measured comparison that fixed this order is in docs/solvers.md.
"""

from __future__ import annotations

import os

import numpy as np
from scipy import sparse

from formulations.solvers.backends import amg, cholmod, pardiso, splu  # noqa: F401 (registers)
from formulations.solvers.backends.base import (
    REGISTRY,
    Backend,
    BackendError,
    CondensedFactor,
    FactorisationError,
    Solve,
    register_backend,
    unregister_backend,
)

__all__ = ["BACKENDS", "Backend", "BackendError", "CondensedFactor", "FactorisationError",
           "available_backends", "backend_names", "check_backend", "condenses",
           "default_backend", "factorise", "factorise_condensed", "iterative", "register_backend",
           "unregister_backend"]


DENSE_COPIES = 3  # the back-end's Schur array, its Cholesky factor, one product of that size


def backend_names() -> tuple[str, ...]:
    """Every registered back-end, the preferred first."""
    return tuple(sorted(REGISTRY.names(), key=lambda name: REGISTRY.get(name).rank))


BACKENDS = backend_names()  # the built-in ones


def available_backends() -> tuple[str, ...]:
    return tuple(name for name in backend_names() if not REGISTRY.get(name).missing)


def default_backend() -> str:
    return available_backends()[0]


def check_backend(backend: str | None) -> str:
    """The back-end to use for ``backend`` (None means the default), or a clear error."""
    if backend is None:
        return default_backend()
    if backend not in REGISTRY.names():
        raise BackendError(f"backend={backend!r} is not one of {', '.join(backend_names())}")
    if backend not in available_backends():
        raise BackendError(f"backend={backend!r} is not available: {REGISTRY.get(backend).missing}")
    return backend


def condenses(backend: str | None) -> bool:
    """Whether ``backend`` gives the Schur complement (the condensed active-set route)."""
    return REGISTRY.get(check_backend(backend)).condense is not None


def iterative(backend: str | None) -> bool:
    """Whether ``backend`` solves by iterations (``amg``) instead of a factorisation."""
    return REGISTRY.get(check_backend(backend)).iterative


def factorise(K: sparse.spmatrix, backend: str | None = None,
              near_null: np.ndarray | None = None) -> Solve:
    """A plain factorisation of K: the linear-solve floor every contact solve is measured
    against (same back-end, same ordering options as ``factorise_condensed``). An iterative
    back-end builds its preconditioner instead, with the rigid-body modes ``near_null``."""
    chosen = REGISTRY.get(check_backend(backend))
    if chosen.iterative:
        return chosen.factorise(sparse.csr_matrix(K), near_null)
    return chosen.factorise(sparse.csc_matrix(K))


def check_dense_block(size: int) -> None:
    """FactorisationError when DENSE_COPIES dense size x size blocks would not fit in the
    memory available now: the Schur complement is dense, and a back-end that cannot allocate
    it may crash the process instead of failing (PARDISO did, at 3D P2 Nitsche's Schur set of
    every DOF of the tetrahedra on Gamma_C)."""
    need = DENSE_COPIES * 8.0 * size**2
    available = os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    if need > available:
        raise FactorisationError(
            f"the dense Schur block of {size} contact DOFs needs {need / 2**30:.1f} GiB "
            f"({DENSE_COPIES} copies), more than the {available / 2**30:.1f} GiB available")


def factorise_condensed(K: sparse.spmatrix, contact: np.ndarray,
                        backend: str | None = None) -> CondensedFactor:
    backend = check_backend(backend)
    condense = REGISTRY.get(backend).condense
    if condense is None:
        raise BackendError(f"backend={backend!r} gives no cheap Schur complement; "
                           f"{', '.join(b for b in available_backends() if condenses(b))} "
                           "do (the augmented iteration is used instead)")
    K = sparse.csc_matrix(K)
    contact = np.unique(np.asarray(contact, dtype=np.int64))
    check_dense_block(contact.size)
    is_contact = np.zeros(K.shape[0], dtype=bool)  # a mask, not a sorted set difference
    is_contact[contact] = True
    interior = np.flatnonzero(~is_contact)
    return condense(K, interior, contact)

"""What every back-end provides, and the registry they add themselves to (see the package
docstring)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy import linalg, sparse

from scenes.registry import Registry

Solve = Callable[[np.ndarray], np.ndarray]


class BackendError(ValueError):
    """An unknown or unavailable back-end was asked for."""


class FactorisationError(RuntimeError):
    """A back-end could not factorise K (not positive definite, out of memory, ...)."""


@dataclass(frozen=True, eq=False)
class CondensedFactor:
    """A factorisation of K (``solve``) and the lower Cholesky factor of S_C on ``contact``."""

    backend: str
    contact: np.ndarray
    solve: Solve
    schur_cholesky: np.ndarray
    phases: tuple[tuple[str, float], ...] = ()  # (phase, seconds) of the factorisation

    def condensed(self, B: sparse.spmatrix) -> np.ndarray:
        """B K^-1 B' for a B whose columns vanish outside ``contact`` (dense, m x m)."""
        W = linalg.solve_triangular(self.schur_cholesky, B[:, self.contact].T.toarray(),
                                    lower=True, check_finite=False)
        return W.T @ W


@dataclass(frozen=True)
class Backend:
    """``factorise(K) -> solve``; ``condense(K, interior, contact) -> CondensedFactor`` or None
    when the back-end has no cheap Schur complement; ``rank``: the default is the available
    back-end of lowest rank; ``missing``: why it cannot be used here ('' when it can);
    ``memory_gib``: the measured peak memory of a whole P1 level on this route, (base GiB, GiB
    per DOF) (bench.sequence.memory; None: not measured, the steepest measured line is used);
    ``iterative``: ``factorise(K, near_null)`` returns an iterative solve (no factorisation;
    ``near_null``: K's rigid-body modes, or None); ``memory_gib_3d``: the measured 3D line of a
    back-end whose memory stays linear in N (no fill), else None."""

    name: str
    rank: int
    factorise: Callable[[sparse.csc_matrix], Solve]
    condense: Callable[[sparse.csc_matrix, np.ndarray, np.ndarray], CondensedFactor] | None
    missing: str = ""
    description: str = ""
    memory_gib: tuple[float, float] | None = None
    iterative: bool = False
    memory_gib_3d: tuple[float, float] | None = None  # a measured 3D line (bench.sequence.memory)


REGISTRY = Registry("back-end")


def register_backend(backend: Backend) -> Backend:
    return REGISTRY.register(backend.name, backend.description)(backend)


def unregister_backend(name: str) -> None:
    REGISTRY.unregister(name)

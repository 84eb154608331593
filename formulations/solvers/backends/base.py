"""What every back-end provides, and the registry they add themselves to (see the package
docstring)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy import linalg, sparse

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
    back-end of lowest rank; ``missing``: why it cannot be used here ('' when it can)."""

    name: str
    rank: int
    factorise: Callable[[sparse.csc_matrix], Solve]
    condense: Callable[[sparse.csc_matrix, np.ndarray, np.ndarray], CondensedFactor] | None
    missing: str = ""


REGISTRY: dict[str, Backend] = {}


def register_backend(backend: Backend) -> Backend:
    if backend.name in REGISTRY:
        raise ValueError(f"back-end {backend.name!r} is registered twice")
    REGISTRY[backend.name] = backend
    return backend


def unregister_backend(name: str) -> None:
    del REGISTRY[name]

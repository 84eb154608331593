"""``pardiso``: Intel MKL PARDISO, through the ``mkl`` wheel that pypardiso finds (``pip install
.`` brings both on x86_64).

PARDISO computes the Schur complement of K on the contact DOFs inside its factorisation: with
the contact DOFs flagged in ``perm`` and iparm[35] = 2 it eliminates the interior, returns S_C
as a dense matrix and keeps the partial factor, with which the same handle still solves with
the whole K (docs/theory.md, section 11). Both factorisations use parallel nested dissection
(iparm[1] = 3) and the two-level parallel factorisation (iparm[23] = 1), so the contact solve
and the plain linear solve are compared like with like.
"""

from __future__ import annotations

import ctypes
import functools
import importlib.util
import time
import weakref

import numpy as np
from scipy import linalg, sparse

from formulations.solvers.backends.base import (
    Backend,
    CondensedFactor,
    FactorisationError,
    register_backend,
)

SPD = 2  # PARDISO's mtype for real symmetric positive definite matrices
IPARM = {0: 1,    # these values, not the defaults
         1: 3,    # parallel nested-dissection ordering
         9: 8,    # pivot perturbation 1e-8 (only used for indefinite matrices)
         23: 1,   # two-level parallel factorisation
         34: 1}   # zero-based indices
SCHUR = 35        # iparm index: 2 = Schur complement plus partial factorisation
ERRORS = {-1: "input inconsistent", -2: "not enough memory", -3: "reordering problem",
          -4: "zero pivot (K is not positive definite?)", -7: "diagonal matrix is singular",
          -8: "32-bit integer overflow"}


@functools.cache
def _pardiso():
    from pypardiso import PyPardisoSolver

    function = PyPardisoSolver().libmkl.pardiso
    pointer, i32 = ctypes.POINTER, ctypes.c_int32
    function.argtypes = [pointer(ctypes.c_int64)] + [pointer(i32)] * 5 + [
        ctypes.c_void_p] + [pointer(i32)] * 6 + [ctypes.c_void_p, ctypes.c_void_p, pointer(i32)]
    function.restype = None
    return function


class _Handle:
    """One PARDISO factorisation of an SPD K (its upper triangle); freed with the object."""

    def __init__(self, K: sparse.csc_matrix, schur: np.ndarray | None = None):
        upper = sparse.triu(K, format="csr")
        upper.sort_indices()
        self.n = K.shape[0]
        self.arrays = (np.ascontiguousarray(upper.data, dtype=np.float64),
                       upper.indptr.astype(np.int32), upper.indices.astype(np.int32),
                       np.zeros(64, dtype=np.int64), np.zeros(64, dtype=np.int32),
                       np.zeros(self.n, dtype=np.int32))
        iparm, perm = self.arrays[4], self.arrays[5]
        for index, value in IPARM.items():
            iparm[index] = value
        if schur is not None:
            perm[schur], iparm[SCHUR] = 1, 2
        weakref.finalize(self, _release, self.n, self.arrays)

    def run(self, phase: int, rhs: np.ndarray, out: np.ndarray) -> None:
        _call(self.n, self.arrays, phase, rhs, out)

    def solve(self, b: np.ndarray) -> np.ndarray:
        rhs = np.asfortranarray(b, dtype=np.float64)
        out = np.zeros_like(rhs)
        self.run(33, rhs, out)
        return np.ascontiguousarray(out)


def _release(n, arrays) -> None:
    """Free PARDISO's memory of a handle; a handle never factorised (a run ended by a signal
    between the two) holds none, and a failure to free is no error of the solve."""
    if not arrays[3].any():  # pt: PARDISO's internal pointers, zero until phase 11 or 12
        return
    try:
        _call(n, arrays, -1, np.zeros(1), np.zeros(1))
    except FactorisationError:
        pass


def _call(n, arrays, phase, rhs, out) -> None:
    data, indptr, indices, pt, iparm, perm = arrays
    i32, pointer, error = ctypes.c_int32, ctypes.POINTER(ctypes.c_int32), ctypes.c_int32(0)
    nrhs = 1 if rhs.ndim == 1 else rhs.shape[1]
    _pardiso()(pt.ctypes.data_as(ctypes.POINTER(ctypes.c_int64)), ctypes.byref(i32(1)),
               ctypes.byref(i32(1)), ctypes.byref(i32(SPD)), ctypes.byref(i32(phase)),
               ctypes.byref(i32(n)), data.ctypes.data, indptr.ctypes.data_as(pointer),
               indices.ctypes.data_as(pointer), perm.ctypes.data_as(pointer),
               ctypes.byref(i32(nrhs)), iparm.ctypes.data_as(pointer), ctypes.byref(i32(0)),
               rhs.ctypes.data, out.ctypes.data, ctypes.byref(error))
    if error.value != 0:
        raise FactorisationError(f"PARDISO phase {phase} failed with error {error.value}: "
                                 f"{ERRORS.get(error.value, 'see the MKL documentation')}")


def factorise(K):
    handle = _Handle(K)
    handle.run(12, np.zeros(1), np.zeros(1))  # analysis and factorisation
    return handle.solve


def condense(K, interior, contact) -> CondensedFactor:
    clock = time.perf_counter()
    if interior.size == 0:  # nothing to eliminate (PARDISO refuses): S_C is K itself
        solve, schur = factorise(K), K.toarray()
        phases = [("order", 0.0), ("factorise", time.perf_counter() - clock)]
    else:
        handle = _Handle(K, schur=contact)
        handle.run(11, np.zeros(1), np.zeros(1))
        phases = [("order", time.perf_counter() - clock)]
        clock = time.perf_counter()
        schur = np.zeros((contact.size, contact.size))
        handle.run(22, np.zeros(1), schur)  # S_C is written into the solution array
        solve = handle.solve
        phases.append(("factorise", time.perf_counter() - clock))
    clock = time.perf_counter()
    try:
        L_CC = linalg.cholesky(schur, lower=True, check_finite=False)
    except linalg.LinAlgError as error:
        raise FactorisationError(f"the Schur complement is not positive definite: {error}") \
            from None
    phases.append(("schur block", time.perf_counter() - clock))
    return CondensedFactor("pardiso", contact, solve, L_CC, tuple(phases))


register_backend(Backend(
    "pardiso", rank=0, factorise=factorise, condense=condense,
    missing="" if importlib.util.find_spec("pypardiso") else
    "install pypardiso (pip install pypardiso; Intel MKL, x86_64 only)",
    description="Intel MKL PARDISO (pypardiso); S_C from its partial factorisation",
    # peak 0.23 / 0.52 / 2.58 GiB at 10 512 / 100 800 / 992 640 DOFs (bench scaling): the line
    # through the first and the last, 0.86 x the middle point
    memory_gib=(0.2048, 2.393e-6)))

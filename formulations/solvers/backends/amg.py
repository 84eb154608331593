"""``amg``: Krylov iterations preconditioned by smoothed-aggregation algebraic multigrid
(PyAMG), with the rigid-body modes as near-null space (docs/theory.md, section 16).

No factorisation and no dense block: the memory is O(N) and a solve costs a bounded number of
V-cycles on a mesh-independent hierarchy. ``factorise(K, near_null)`` builds the hierarchy once
and returns a solve that runs conjugate gradients (symmetric K) or GMRES (a nonsymmetric
Jacobian: Nitsche with theta != 1) to the relative residual ``RTOL``. A solve that does not
reach RTOL raises ``FactorisationError`` with the residual reached: never an inaccurate answer
passed on. The hierarchy of a symmetric K comes from ``amg_hierarchy`` (PyAMG's steps, every
level in single precision); a nonsymmetric one from PyAMG's ``smoothed_aggregation_solver``.

There is no cheap Schur complement, so the active-set solver runs its projected iteration
(``formulations.solvers.projected``) and the semismooth Newton its sparse steps on this
back-end. Rigid-body modes come with the problem (``near_null``); without them the
translations of each component are lost and PyAMG falls back to constants (slower, not wrong).
"""

from __future__ import annotations

import importlib.util
from dataclasses import dataclass, field

import numpy as np
from scipy import sparse
from scipy.sparse.linalg import LinearOperator, cg, gmres

from formulations.solvers.backends.amg_hierarchy import (
    MAX_COARSE,
    smoothed_aggregation,
    strength_per_level,
)
from formulations.solvers.backends.base import Backend, FactorisationError, register_backend

# relative residual |b - K x| / |b| of every solve. Energy-norm difference to the direct
# back-end against it (vi P1 on paper-3d at 13 872 DOFs; nitsche P2 on paper at 131 584):
# 1e-8 -> 3.0e-9 / 3.1e-12, 1e-9 -> 3.5e-10 / 4.1e-13, 1e-10 -> 3.7e-11 / 1.2e-13, so 1e-10
# keeps the 1e-8 agreement with two orders to spare
RTOL = 1e-10
MAX_ITERATIONS = 2000
SYMMETRIC = 1e-12  # max |K - K'| / max |K| below which K is treated as symmetric (round-off)
# the hierarchy and its V-cycle in single precision: the Krylov iteration stays in double and
# corrects the preconditioner's round-off. vi P1 on paper-3d at 104 544 DOFs, CG to 1e-10:
# 30 iterations in both precisions, 0.039 against 0.056 s per iteration (the V-cycle's sweeps
# read half the bytes), and the hierarchy takes half the memory
CYCLE_DTYPE = np.float32
# one forward Gauss-Seidel sweep before the coarse correction and one backward after it (a
# symmetric V-cycle, half the sweeps of PyAMG's default): the same contact solve at 104 544
# DOFs took 124 V-cycles in 4.4 s against 102 in 4.8 s
SMOOTHING = (("block_gauss_seidel", {"sweep": "forward"}),
             ("block_gauss_seidel", {"sweep": "backward"}))


@dataclass(eq=False)
class IterativeSolve:
    """K^-1 b by preconditioned Krylov iterations; ``iterations`` counts each solve's."""

    K: sparse.csr_matrix
    preconditioner: object
    symmetric: bool
    iterations: list[int] = field(default_factory=list)
    max_iterations: int | None = None  # None: MAX_ITERATIONS
    by_rule: list[bool] = field(default_factory=list)  # a stopping rule ended the solve

    def for_matrix(self, K: sparse.spmatrix, max_iterations: int) -> IterativeSolve:
        """A solve of another matrix K with this hierarchy as its preconditioner, that gives
        up (``FactorisationError``) after ``max_iterations``."""
        K = sparse.csr_matrix(K)
        return IterativeSolve(K, self.preconditioner, is_symmetric(K),
                              max_iterations=max_iterations)

    def __call__(self, b: np.ndarray, rtol: float | None = None, done=None) -> np.ndarray:
        """K^-1 b to the relative residual ``rtol`` (None: RTOL), or (CG only) until
        ``done(r, x)`` holds for the iterate x and its residual r = b - K x (a stopping rule's;
        ``by_rule`` records which ended each solve)."""
        rtol = RTOL if rtol is None else rtol
        b = np.asarray(b, dtype=float)
        if b.ndim == 2:
            return np.column_stack([self(column, rtol=rtol) for column in b.T])
        norm = np.linalg.norm(b)
        if norm == 0.0:
            return np.zeros_like(b)
        count = [0]
        done = done if self.symmetric else None  # GMRES hands out no iterate to judge

        def tick(x):
            count[0] += 1
            if done is not None and done(b - self.K @ x, x):
                raise RuleMet(np.array(x, copy=True))

        method = cg if self.symmetric else gmres
        extra = {} if self.symmetric else {"restart": 60, "callback_type": "pr_norm"}
        limit = self.max_iterations or MAX_ITERATIONS
        try:
            x, info = method(self.K, b, rtol=rtol, atol=0.0, maxiter=limit,
                             M=self.preconditioner, callback=tick, **extra)
        except RuleMet as met:
            self.iterations.append(count[0])
            self.by_rule.append(True)
            return met.x
        self.iterations.append(count[0])
        self.by_rule.append(False)
        residual = np.linalg.norm(b - self.K @ x) / norm
        if info != 0 and residual > 10 * rtol:
            raise FactorisationError(f"amg: {'CG' if self.symmetric else 'GMRES'} reached "
                                     f"a relative residual of {residual:.1e}, not {rtol:.0e}, "
                                     f"in {count[0]} iterations")
        return x


class RuleMet(Exception):  # noqa: N818 - not an error: how a stopping rule ends scipy's CG
    """Carries the iterate at which a stopping rule ended a Krylov solve."""

    def __init__(self, x: np.ndarray):
        super().__init__("stopping rule met")
        self.x = x


def is_symmetric(K: sparse.spmatrix) -> bool:
    scale = abs(K).max()
    return bool(scale == 0.0 or abs(K - K.T).max() <= SYMMETRIC * scale)


def factorise(K: sparse.spmatrix, near_null: np.ndarray | None = None) -> IterativeSolve:
    """The smoothed-aggregation hierarchy of K (``near_null``: its rigid-body modes, n x 3 in
    2D or n x 6 in 3D) and the solve that uses it as preconditioner."""
    import pyamg

    K = sparse.csr_matrix(K)
    symmetric = is_symmetric(K)
    modes = np.ones((K.shape[0], 1)) if near_null is None else near_null
    if symmetric:  # PyAMG's steps, its spectral radius estimated in single precision
        hierarchy = smoothed_aggregation(K.astype(CYCLE_DTYPE), modes)
    else:
        hierarchy = pyamg.smoothed_aggregation_solver(
            K.astype(CYCLE_DTYPE), B=np.asarray(modes, dtype=CYCLE_DTYPE),
            symmetry="nonsymmetric", strength=strength_per_level(),
            max_coarse=MAX_COARSE, coarse_solver="splu")
    in_single(hierarchy)
    return IterativeSolve(K, VCycle(hierarchy), symmetric)


def in_single(hierarchy) -> None:
    """Every level's operator and transfer in CYCLE_DTYPE."""
    from pyamg.relaxation.smoothing import change_smoothers

    for level in hierarchy.levels:
        for name in ("A", "P", "R"):
            if hasattr(level, name):
                setattr(level, name, single(getattr(level, name)))
    change_smoothers(hierarchy, SMOOTHING[0], SMOOTHING[1])


def single(M: sparse.spmatrix) -> sparse.spmatrix:
    """M in CYCLE_DTYPE on its own index arrays (``astype`` would sum duplicates first); a
    transfer with 1 x k blocks as CSR, whose products are faster than BSR's (paper-3d,
    104 544 DOFs, k = 6: 3.1 against 3.7 ms). The finest operator, built from K in
    CYCLE_DTYPE, is kept as it is rather than copied."""
    if M.format == "bsr" and 1 in M.blocksize:
        M = M.tocsr()
    if M.dtype == CYCLE_DTYPE:
        return M
    if M.format not in ("csr", "bsr"):
        return M.astype(CYCLE_DTYPE)
    return type(M)((M.data.astype(CYCLE_DTYPE), M.indices, M.indptr), shape=M.shape)


class VCycle(LinearOperator):
    """One V-cycle from a zero initial guess, on double vectors, in CYCLE_DTYPE: PyAMG's
    ``aspreconditioner`` runs its ``solve``, which adds two residuals on the finest level to
    every cycle (a quarter of its cost on paper-3d at 104 544 DOFs)."""

    def __init__(self, hierarchy):
        super().__init__(dtype=float, shape=hierarchy.levels[0].A.shape)
        self.hierarchy = hierarchy
        self.levels, self.coarse = hierarchy.levels, hierarchy.coarse_solver

    def _matvec(self, b):
        return self.cycle(0, np.asarray(b, dtype=CYCLE_DTYPE).ravel()).astype(float)

    def cycle(self, depth: int, b: np.ndarray) -> np.ndarray:
        level = self.levels[depth]
        if depth == len(self.levels) - 1:
            return np.asarray(self.coarse(level.A, b), dtype=CYCLE_DTYPE)
        x = np.zeros_like(b)
        level.presmoother(level.A, x, b)
        x += level.P @ self.cycle(depth + 1, level.R @ (b - level.A @ x))
        level.postsmoother(level.A, x, b)
        return x


register_backend(Backend(
    "amg", rank=3, factorise=factorise, condense=None,
    missing="" if importlib.util.find_spec("pyamg") else "pyamg is not installed",
    description="conjugate gradients with smoothed-aggregation AMG (PyAMG), rigid-body "
                "near-null space; no factorisation (the projected active-set iteration)",
    iterative=True,
    # bench scaling --backend amg: peak of a whole level (assembly, solve, estimator) 0.54 /
    # 3.24 GiB at 100 800 / 992 640 DOFs (2D, mixed; with the float32 hierarchy, built from a
    # float32 copy of K, against 0.46 / 2.73 before it), the line through them. 3D: 0.97 GiB at
    # 104 544 DOFs (one level, vi; reports/amg/scaling-3d.md) and 15.24 GiB, the peak of a whole
    # adaptive sequence to 2 736 186 DOFs (paper-3d, vi, residual; it holds the previous level
    # too, and its last refinement), the line through them (3.36 GiB at 545 832: the single
    # level measured 2.78)
    memory_gib=(0.2348, 3.027e-6), memory_gib_3d=(0.4031, 5.422e-6)))

"""The smoothed-aggregation hierarchy of a symmetric K for the ``amg`` back-end (docs/theory.md,
section 16): PyAMG's own steps and defaults, with the spectral radius estimated in the
operator's single precision from a fixed start vector.

Each level, as PyAMG's ``smoothed_aggregation_solver`` builds it: symmetric strength of
connection, standard aggregation, the near-null candidates improved by four symmetric block
Gauss-Seidel sweeps on A B = 0 (finest level only), the tentative prolongator T fitted to
them, one Jacobi smoothing step P = T - omega / rho(D^-1 A) D^-1 A T with omega = 4/3,
R = P' and the Galerkin operator R A P. Two changes:

- the strength threshold: theta = 0 (PyAMG's) on the finest level, COARSE_THETA below it.
  The Galerkin operators hold small couplings that theta = 0 counts as strong, so their
  aggregates grew level by level (paper-3d, 104 544 P1 DOFs: 25 nodes per aggregate on the
  finest level, 113 on the next) and the coarse correction weakened as levels were added;
- rho: PyAMG starts its Arnoldi iteration from a random double vector, so every product with
  the single-precision D^-1 A converted the whole matrix to double (5.3 s of a 15-s set-up at
  5.5e5 DOFs on paper-3d) and the hierarchy differed from run to run. Here the same estimator
  (``approximate_spectral_radius``, relative tolerance 1e-2) starts from a seeded vector in
  A's precision, and omega / rho keeps that precision, so P and the coarse operators stay in
  it.
"""

from __future__ import annotations

import numpy as np
from scipy import sparse

OMEGA = 4.0 / 3.0  # PyAMG's Jacobi damping for the prolongation smoother
# strength threshold below the finest level. paper-3d, vi P1, CG iterations of one linear
# solve at 9 450 / 104 544 / 545 832 DOFs: theta = 0 on every level 22 / 42 / 47; 0.02 on
# every level 22 / 33 / 34; 0 on the finest and 0.04 below 22 / 32 / 33 (the 545 832-DOF
# solve 11.9 s against 16.7 s; its coarsest level 2 304 unknowns against 480)
COARSE_THETA = 0.04
MAX_COARSE = 500  # nodes on the coarsest level, solved by a sparse LU
MAX_LEVELS = 10  # PyAMG's default
# PyAMG's default improvement of the candidates on the finest level
IMPROVE = ("block_gauss_seidel", {"sweep": "symmetric", "iterations": 4})
SEED = 0  # the spectral-radius estimate's start vector: the same hierarchy on every run


def strength_per_level() -> list:
    """PyAMG's ``strength`` argument for the thresholds above: theta = 0 on the finest level,
    COARSE_THETA below it (a new list: PyAMG extends it in place)."""
    return [("symmetric", {"theta": 0.0}), ("symmetric", {"theta": COARSE_THETA})]


def smoothed_aggregation(A: sparse.csr_matrix, B: np.ndarray):
    """The hierarchy (a PyAMG ``MultilevelSolver``, coarsest level solved by ``splu``) of the
    symmetric A with near-null space B (n x k), in A's precision; smoothers are set by the
    caller."""
    from pyamg.multilevel import MultilevelSolver
    from pyamg.util.utils import get_blocksize

    finest = MultilevelSolver.Level()
    finest.A, finest.B = A, np.asarray(B, dtype=A.dtype).reshape(A.shape[0], -1)
    finest.A.symmetry = "symmetric"
    levels = [finest]
    while (len(levels) < MAX_LEVELS
           and levels[-1].A.shape[0] // get_blocksize(levels[-1].A) > MAX_COARSE):
        levels.append(coarser(levels[-1], finest=len(levels) == 1))
    return MultilevelSolver(levels, coarse_solver="splu")


def coarser(level, finest: bool):
    """The next level below ``level``, whose P and R are set on the way (module docstring);
    ``finest``: ``level`` is the finest (theta = 0 and improved candidates)."""
    from pyamg.aggregation import fit_candidates, standard_aggregation
    from pyamg.multilevel import MultilevelSolver
    from pyamg.relaxation.utils import relaxation_as_linear_operator
    from pyamg.strength import symmetric_strength_of_connection

    A = level.A
    theta = 0.0 if finest else COARSE_THETA
    aggregates, _ = standard_aggregation(symmetric_strength_of_connection(A, theta=theta))
    if finest:
        zero = np.zeros((A.shape[0], 1), dtype=A.dtype)
        level.B = relaxation_as_linear_operator(IMPROVE, A, zero) @ level.B
    T, B_coarse = fit_candidates(aggregates, level.B)
    level.P = jacobi_smoothed(A, T)
    level.R = level.P.T
    below = MultilevelSolver.Level()
    below.A, below.B = level.R @ A @ level.P, B_coarse
    below.A.symmetry = "symmetric"
    return below


def jacobi_smoothed(A: sparse.spmatrix, T: sparse.spmatrix) -> sparse.spmatrix:
    """T - omega / rho(D^-1 A) D^-1 A T, every factor in A's precision."""
    from pyamg.util.linalg import approximate_spectral_radius
    from pyamg.util.utils import get_diagonal, scale_rows

    D_inv_A = scale_rows(A, get_diagonal(A, inv=True), copy=True)
    start = np.random.default_rng(SEED).random(A.shape[0]).astype(A.dtype)
    rho = approximate_spectral_radius(D_inv_A, initial_guess=start)
    return T - D_inv_A @ T * A.dtype.type(OMEGA / rho)

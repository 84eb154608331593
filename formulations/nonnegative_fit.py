"""Bound-constrained least squares, argmin_{x >= 0} ||A x - b||^2 + ||w x||^2, by Clarabel's
interior-point method on the sparse normal equations: the non-negative pressures that
reproduce nodal reactions (``formulations.surface_nodes`` for vi's P2 pressure on a 3D
contact surface, ``estimators.nonnegative_traction`` for the guaranteed bound's lambda*)."""

from __future__ import annotations

import clarabel
import numpy as np
from scipy import sparse

TOLERANCE = 1e-12  # the problems are small and well scaled: solved to round-off


def bounded_least_squares(A: sparse.spmatrix, b: np.ndarray, weights: np.ndarray
                          ) -> np.ndarray | None:
    """x >= 0 minimising ||A x - b||^2 + ||weights * x||^2, or None if Clarabel does not
    solve it (the caller then keeps its fallback)."""
    n = A.shape[1]
    P = sparse.triu(2 * (A.T @ A + sparse.diags(weights**2))).tocsc()
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    settings.tol_gap_abs = settings.tol_gap_rel = settings.tol_feas = TOLERANCE
    solver = clarabel.DefaultSolver(P, -2 * (A.T @ b), -sparse.eye(n, format="csc"),
                                    np.zeros(n), [clarabel.NonnegativeConeT(n)], settings)
    solution = solver.solve()
    if solution.status not in (clarabel.SolverStatus.Solved, clarabel.SolverStatus.AlmostSolved):
        return None
    return np.maximum(np.asarray(solution.x), 0.0)

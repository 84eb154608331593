"""Stability diagnostics of a discrete contact solution (docs/theory.md, section 5), computed
from the assembled arrays and the returned solution, never taken from a solver.

* ``inf_sup_constant``: the discrete inf-sup constant of a formulation with a multiplier space
  (the mixed method), for the contact part,

      beta_h = min_mu sup_v (mu, v_n)_{Gamma_C} / (||v||_K ||mu||_{-1/2,h}),

  with ||v||_K^2 = v'Kv / E (the energy norm of the QP, E = objective_scale) and the
  mesh-dependent H^{-1/2} norm ||mu||_{-1/2,h}^2 = sum_S H_S ||mu||_{0,S}^2 (equivalent to the
  H^{-1/2} norm on discrete multipliers of a quasi-uniform contact mesh; Haslinger, Hlavacek,
  Necas 1996). Since (mu, v_n) = mu'Bv, the sup over v is (mu' B K^-1 B' mu)^(1/2), so beta_h^2
  is the smallest eigenvalue of the pencil (E B K^-1 B', M) with M the Gram matrix of the
  multiplier norm (``Discretisation.multiplier_gram``). Dimensionless; bounded below under
  refinement exactly when the pair is uniformly stable. B K^-1 B' is the active-set solver's
  condensed system on its condensed route (pardiso, cholmod; passed as ``condensed``);
  otherwise it costs one factorisation of K and m solves.
* ``pressure_oscillation``: TV(lambda_h) / (2 max lambda_h) along Gamma_C, with lambda_h taken
  as 0 beyond the ends of Gamma_C: 1 for any single-hump (or constant) pressure, larger for every
  extra wiggle; a checkerboard multiplier drives it up with the number of segments. 0 when
  lambda_h = 0.
"""

from __future__ import annotations

import numpy as np
from scipy import linalg, sparse

from formulations.base import DiscreteSolution
from formulations.solvers.backends import factorise

SOLVE_BLOCK = 8  # right-hand sides per solve (SuperLU slows down with many at once)


def inf_sup_constant(discretisation, backend: str | None = None,
                     condensed: np.ndarray | None = None) -> float:
    """beta_h (see the module docstring); NaN for a formulation without a multiplier space.
    ``condensed``: B K^-1 B' if the caller already has it (else computed here)."""
    qp, multiplier_gram = discretisation.qp, discretisation.multiplier_gram
    if multiplier_gram is None or qp is None or qp.m == 0:
        return float("nan")
    if condensed is None:
        solve = factorise(qp.K, backend, qp.near_null)
        Bt = qp.B.T.tocsc()
        X = np.column_stack([solve(Bt[:, k:k + SOLVE_BLOCK].toarray())
                             for k in range(0, qp.m, SOLVE_BLOCK)])
        condensed = qp.B @ X
    S = qp.objective_scale * np.asarray(condensed)
    S = 0.5 * (S + S.T)
    gram = (multiplier_gram.toarray() if sparse.issparse(multiplier_gram)
            else np.asarray(multiplier_gram))
    smallest = linalg.eigh(S, np.diag(gram) if gram.ndim == 1 else gram, eigvals_only=True,
                           subset_by_index=[0, 0])[0]
    return float(np.sqrt(max(smallest, 0.0)))


def pressure_oscillation(solution: DiscreteSolution, samples: int = 5) -> float:
    """TV(lambda_h) / (2 max lambda_h) along Gamma_C (see the module docstring); NaN on a 3D
    contact surface, which has no order along it."""
    return solution.trace.variation(solution.pressure, samples)

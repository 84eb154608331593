"""A non-negative auxiliary contact traction lambda* for the guaranteed bound (docs/theory.md,
section 13.3).

The bound charges a negative part of lambda* with the trace constant, N = C_T ||lambda*_-||.
The L2 representative of u_h's discrete reaction in continuous P1 (``guaranteed_contact.
balanced_traction``) changes sign where the contact zone is a few facets wide, although the
reactions R_a of a vi or penalty solution are >= 0. This one is a polynomial of degree k on
each contact facet with non-negative Bernstein coefficients (so >= 0) whose moments against the
hat functions are R_a: a bound-constrained least-squares problem on Gamma_C,

    min_{x >= 0} sum_a (G x - R)_a^2 / l_a + EPSILON^2 ||lambda*||^2_{0,Gamma_C},

(l_a the length of a's contact facets; the small second term picks one of the many solutions).
What it leaves unbalanced (the least squares' round-off; more where no non-negative traction
balances: an isolated contact node next to nodes without reaction, a P2/P3 reaction that is
negative somewhere) is corrected as for lambda_h (``balanced_traction``), and the estimate
takes this traction only where it gives the smaller contact terms.
"""

from __future__ import annotations

import numpy as np
from scipy import sparse
from scipy.special import comb

from estimators.guaranteed.contact_extension import vertex_normals
from estimators.guaranteed.guaranteed_contact import FacetPolynomial, projected_pressure
from formulations.nonnegative_fit import bounded_least_squares

EPSILON = 1e-4  # weight of ||lambda*|| against the balance (relative leftover ~1e-6, measured)


def hat_moments(trace, k: int) -> sparse.csr_matrix:
    """int_e B_j psi_a over the contact facets e, (n_vertices, n_f (k + 1)): B_j the Bernstein
    polynomials of degree k on each facet, psi_a the hat function of vertex a."""
    j = np.arange(k + 1)
    at_start = (k + 1 - j) / ((k + 1) * (k + 2))  # int_0^1 B_j (1 - t) dt
    at_end = (j + 1) / ((k + 1) * (k + 2))        # int_0^1 B_j t dt
    columns = np.arange(trace.size * (k + 1)).reshape(trace.size, k + 1)
    rows = np.concatenate([np.repeat(v, k + 1) for v in trace.vertices])
    values = np.concatenate([(trace.length[:, None] * m).ravel() for m in (at_start, at_end)])
    return sparse.coo_matrix((values, (rows, np.tile(columns.ravel(), 2))),
                             shape=(trace.mesh.p.shape[1], columns.size)).tocsr()


def nonnegative_pressure(trace, reaction: np.ndarray, clamped: np.ndarray, k: int
                         ) -> FacetPolynomial:
    """lambda* >= 0 of the module docstring for the per-vertex reaction (n_vertices, 2) (the
    same sign convention as ``balanced_traction`` with lambda_h = 0), in Legendre form."""
    on = np.unique(np.concatenate(trace.vertices))
    on = on[~clamped[on]]
    G = hat_moments(trace, k)[on]
    R = -(reaction[on] * vertex_normals(trace)[:, on].T).sum(axis=1)
    row_scale = 1 / np.sqrt(2 * np.asarray(G.sum(axis=1)).ravel())  # int psi_a = l_a / 2
    # ||sum_j x_j B_j||^2 <= sum_j x_j^2 |e| / (k + 1) (Bernstein: a partition of unity)
    norm = np.repeat(np.sqrt(trace.length / (k + 1)), k + 1)
    x = bounded_least_squares(sparse.diags(row_scale) @ G, row_scale * R, EPSILON * norm)
    # unsolved: lambda* is candidate (ii) of 13.3 again, still a bound
    x = (np.zeros(norm.size) if x is None else x).reshape(trace.size, k + 1)
    return bernstein_polynomial(x)


def bernstein_polynomial(x: np.ndarray) -> FacetPolynomial:
    """sum_j x_j B_j on each contact facet, Bernstein coefficients x (n_f, k + 1), in Legendre
    form (exact: the projection onto P_k keeps a polynomial of degree k)."""
    k = x.shape[1] - 1

    def value(t):
        bernstein = np.array([comb(k, j) * t**j * (1 - t) ** (k - j) for j in range(k + 1)])
        return x @ bernstein

    return projected_pressure(value, k)

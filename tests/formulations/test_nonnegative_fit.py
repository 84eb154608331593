"""Bound-constrained least squares (formulations.nonnegative_fit): the exact minimiser, not
the interior point's approximation of it, on problems whose small weights leave it weakly
determined (as the hat moments of a contact traction do: more coefficients than vertices)."""

import numpy as np
import pytest
from scipy import sparse
from scipy.optimize import lsq_linear

from formulations import nonnegative_fit


def weakly_determined(seed: int):
    """40 rows, 96 unknowns (a null space of 56 directions), weights 1e-4."""
    rng = np.random.default_rng(seed)
    A = (sparse.random(40, 96, density=0.08, random_state=seed, format="csr")
         + sparse.eye(40, 96, format="csr"))
    b = A @ (np.maximum(rng.standard_normal(96), 0.0) * 100) + 5 * rng.standard_normal(40)
    return A, b, np.full(96, 1e-4)


def bvls(A, b, weights):
    """The minimiser by Stark and Parker's finite active-set method on the stacked system."""
    stacked = sparse.vstack([A, sparse.diags(weights)]).toarray()
    return lsq_linear(stacked, np.concatenate([b, np.zeros(weights.size)]),
                      bounds=(0.0, np.inf), method="bvls", tol=1e-15).x


@pytest.mark.parametrize("seed", range(4))
def test_the_fit_is_the_minimiser(seed):
    A, b, weights = weakly_determined(seed)
    x, reference = nonnegative_fit.bounded_least_squares(A, b, weights), bvls(A, b, weights)
    assert x.min() >= 0
    # measured 2.7e-8 .. 6.6e-8 (BVLS's own accuracy at a conditioning of ~1e10), where the
    # interior point's answer alone is 0.24 .. 1.0 off
    assert np.abs(x - reference).max() <= 1e-6 * np.abs(reference).max()


def test_a_change_at_round_off_moves_the_fit_at_round_off():
    """The same problem with b changed by 1e-14 relative (what the thread count does to a
    solution): the fit moves by the round-off of its conditioning (~1e10 here), not along the
    near-null directions where the interior point stops (its answers alone moved by 5 .. 30 %
    on these problems)."""
    for seed in range(4):
        A, b, weights = weakly_determined(seed)
        x = nonnegative_fit.bounded_least_squares(A, b, weights)
        y = nonnegative_fit.bounded_least_squares(A, b * (1 + 1e-14), weights)
        assert np.abs(x - y).max() <= 1e-6 * np.abs(x).max()  # measured 5e-8 .. 9e-8

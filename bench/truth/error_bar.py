"""A reference's estimate of its own energy-norm error (docs/theory.md, section 6.3).

On nested levels L-1, L the differences d_L = ||u_L - u_(L-1)|| are computed exactly
(``bench.measure.nonnested``). If the error decays like e = C N^(-a) and the levels are nearly
orthogonal in the energy norm (Galerkin orthogonality, up to the contact terms),
e_(L-1)^2 = e_L^2 + d_L^2, so

    e_L = d_L / sqrt((N_L / N_(L-1))^(2a) - 1).

The rate a is not assumed: it is the slope of log d over log N on the last RATE_LEVELS
differences (d decays at the rate of e), clipped to [MIN_RATE, MAX_RATE] against a noisy fit. It
is a model, not a bound; it is validated against exact errors (tests/bench/truth).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bench.measure.slope import fit_slope

RATE_LEVELS = 4  # differences fitted for the rate
MIN_RATE, MAX_RATE = 0.25, 2.5  # N^-1/4 (a uniform P1 rate near a crack) .. N^-5/2


@dataclass(frozen=True)
class ErrorBar:
    """The estimated own error of the last level, from its difference to the level before."""

    estimated_error: float
    rate: float  # the fitted a of N^(-a)
    difference: float  # d_L
    ratio: float  # N_L / N_(L-1)


def fitted_rate(ndofs, differences) -> float:
    """-slope of log d against log N over the last RATE_LEVELS differences (d_k belongs to
    level k, k >= 1), clipped to [MIN_RATE, MAX_RATE]; 1/2 (the adaptive P1 rate) from a
    single difference."""
    n = np.asarray(ndofs, dtype=float)[-RATE_LEVELS:]
    d = np.asarray(differences, dtype=float)[-RATE_LEVELS:]
    if d.size < 2:
        return 0.5
    slope = fit_slope(n, d).slope  # the suite's one slope fit
    return float(np.clip(-slope, MIN_RATE, MAX_RATE)) if np.isfinite(slope) else 0.5


def error_bar(ndofs, differences) -> ErrorBar:
    """The error bar of the last of levels with DOFs ``ndofs`` (N_0 ... N_L) and differences
    ``differences`` (d_1 ... d_L, d_k = ||u_k - u_(k-1)||)."""
    if len(differences) != len(ndofs) - 1 or not differences:
        raise ValueError(f"differences={len(differences)} values for {len(ndofs)} levels: "
                         "one fewer than the levels, and at least one, are needed")
    rate = fitted_rate(ndofs[1:], differences)
    ratio = ndofs[-1] / ndofs[-2]
    d = float(differences[-1])
    return ErrorBar(d / float(np.sqrt(max(ratio ** (2 * rate) - 1.0, 1e-12))), rate, d, ratio)

"""Two solutions of one discrete problem compared (the cross-check, the hard cases' loss and
the scaling table's agreement columns)."""

from __future__ import annotations

import numpy as np

PRESSURE_SAMPLES = 5  # equispaced points per contact facet where the pressures are compared


def solution_difference(discretisation, solution, other) -> tuple[float, float]:
    """Relative energy-norm difference of u_h to ``other``'s and max pressure difference (at
    PRESSURE_SAMPLES points per contact facet) relative to max lambda of ``other``. The energy
    norm is relative to max(||u_other||, sqrt(E) d) and the pressure to
    max(max lambda_other, E d / |Gamma_C|), d the QP's gap scale, so that a vanishing solution
    or pressure (nothing touches) is not divided by zero."""
    K = discretisation.elasticity.K
    du = solution.u - other.u
    t = discretisation.trace.samples(PRESSURE_SAMPLES)
    lam, lam_other = solution.pressure(t), other.pressure(t)
    young, gap = discretisation.objective_scale, discretisation.gap_scale
    scale = max(np.sqrt(other.u @ K @ other.u), np.sqrt(young) * gap, 1e-300)
    pressure_scale = max(np.abs(lam_other).max(), young * gap
                         / discretisation.trace.measure.sum(), 1e-300)
    return (float(np.sqrt(du @ K @ du) / scale),
            float(np.abs(lam - lam_other).max() / pressure_scale))

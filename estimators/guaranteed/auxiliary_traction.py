"""The auxiliary contact traction lambda* of the guaranteed bound, chosen among three that
balance u_h on the contact patches, each with four balancing corrections, with its contact
terms (docs/theory.md, section 13.3)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from estimators.guaranteed.constants import domain_constants
from estimators.guaranteed.contact_extension import EXTENSIONS, discrete_gap
from estimators.guaranteed.guaranteed_contact import (
    QUADRATURE,
    ContactBounds,
    ContactTraction,
    FacetPolynomial,
    balanced_traction,
    contact_bound,
    projected_pressure,
    traction_balance,
)
from estimators.guaranteed.nonnegative_traction import nonnegative_pressure
from estimators.guaranteed.strip_extension import relaxed
from formulations.contact.reference_facets import gauss_legendre


def contact_traction(scene, solution, interior, reaction: np.ndarray, clamped: np.ndarray,
                     trace_constant: float | None = None
                     ) -> tuple[ContactTraction, ContactBounds]:
    """lambda* (docs/theory.md, 13.3): of three tractions that balance u_h on the contact
    patches, the one with the smallest terms 2 D + C_T ||lambda*_-|| + sqrt(B) (over the
    extensions d of ``estimators.guaranteed.contact_extension``; no patch problem is solved for
    any). Each is a pressure, projected onto P_k per facet, plus a correction, linear per facet, of
    what u_h does not balance with it: (i) lambda_h (the mixed method balances it exactly);
    (ii) zero, so the correction is the L2 representative of u_h's discrete reaction on
    Gamma_C (for the penalty and Nitsche on coarse contact zones, whose pressure formula peaks
    between the Gauss points that their own equations see); (iii) a non-negative traction
    with the reaction's moments where one exists (``estimators.guaranteed.nonnegative_traction``;
    the correction takes the round-off of its least squares, or what no non-negative traction
    balances). Each takes its correction with the facet weights of ``gap_weights`` too
    (``_chosen``). Returns it with its ``ContactBounds`` for every extension, one-layer and
    relaxed off Gamma_C (the choice between the tractions is made with the one-layer
    fields)."""
    trace, order = solution.trace, solution.elasticity.order
    pressures = [projected_pressure(solution.pressure, order),
                 FacetPolynomial(np.zeros((trace.facets.size, order + 1))),
                 nonnegative_pressure(trace, reaction, clamped, order)]
    defects = [reaction - traction_balance(interior, trace, pressure) for pressure in pressures]
    weights = gap_weights(scene, solution)
    candidates = [balanced_traction(trace, pressure, defect, clamped, weight=weight)
                  for pressure, defect in zip(pressures, defects, strict=True)
                  for weight in weights]
    if trace_constant is None:
        trace_constant = domain_constants(scene).trace
    fields = [extend(scene, solution, clamped) for extend in EXTENSIONS]
    energies = [d.energy(trace, solution.elasticity.lame) for d in fields]  # once per field
    bounds = [tuple(contact_bound(scene, solution, traction, d, energy)
                    for d, energy in zip(fields, energies, strict=True))
              for traction in candidates]
    terms = [min(2 * b.extension + trace_constant * b.negative + np.sqrt(b.complementarity)
                 for b in options) for options in bounds]
    best = _chosen(np.array(terms), len(weights))
    dirichlet = scene.dirichlet_facets(solution.elasticity.mesh)
    strips = relaxed(fields, trace, solution.elasticity.lame, dirichlet)
    sharp = tuple(replace(bound, extension=float(np.sqrt(strip.energies.sum())),
                          energy=strip.energies, field=strip)
                  for bound, strip in zip(bounds[best], strips, strict=True))
    return candidates[best], ContactBounds(marking=bounds[best], sharp=sharp)


# A weighted correction moves lambda*, and sigma* carries the move into A, which the choice
# does not see: on free-boundary, penalty, P3, 5106 DOFs, one with 2 % smaller contact terms
# raised A by 44 %. So a weighted correction is taken only where it cuts them by this much.
WEIGHTED_MARGIN = 0.1


def _chosen(terms: np.ndarray, n_weights: int) -> int:
    """The candidate with the smallest contact terms (candidates pressure by pressure, each
    with the ``n_weights`` weights of ``gap_weights``, None first), a weighted one only if it
    beats the best unweighted by WEIGHTED_MARGIN."""
    best = int(np.argmin(terms))
    plain = int(np.argmin(terms[::n_weights])) * n_weights
    return best if terms[best] <= (1 - WEIGHTED_MARGIN) * terms[plain] else plain


GAP_SCALES = (1e-1, 1e-2, 1e-3)  # s / max_e X_e of the weights tried besides omega = 1


def gap_weights(scene, solution) -> list[np.ndarray | None]:
    """The facet weights of the balancing correction (docs/theory.md, 13.3): None (the
    continuous P1 delta), and omega_e = 1 + X_e / s with X_e the mean of (g - u_hn)_+ on facet
    e and s = GAP_SCALES times its largest value: the correction then keeps off the facets
    where u_h leaves a gap, where lambda*_+ costs slack in B."""
    t, w = gauss_legendre(QUADRATURE)
    gap = np.maximum(discrete_gap(scene, solution, t), 0.0) @ w
    top = gap.max()
    if top <= 0:
        return [None]
    return [None] + [1.0 + gap / (scale * top) for scale in GAP_SCALES]

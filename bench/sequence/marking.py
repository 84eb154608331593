"""Marking strategies for adaptive refinement (docs/theory.md, section 7)."""

from __future__ import annotations

import numpy as np

MARKINGS = ("doerfler", "maximum")


def doerfler(indicators: np.ndarray, theta: float) -> np.ndarray:
    """Doerfler (bulk) marking: the fewest elements whose squared indicators sum to at least
    theta times the total. ``indicators`` are squared element contributions."""
    order = np.argsort(indicators)[::-1]
    cumulative = np.cumsum(indicators[order])
    count = int(np.searchsorted(cumulative, theta * cumulative[-1] * (1 - 1e-12))) + 1
    return np.sort(order[:count])


def maximum(indicators: np.ndarray, theta: float) -> np.ndarray:
    """Maximum marking: every element with eta_T >= theta * max eta_T (eta_T = sqrt of the
    squared indicator)."""
    eta_t = np.sqrt(np.maximum(indicators, 0.0))
    return np.flatnonzero(eta_t >= theta * eta_t.max())


def check_marking(marking: str, theta: float) -> None:
    """Refuse an unknown marking or a theta outside (0, 1], naming the value."""
    if marking not in MARKINGS:
        raise ValueError(f"marking={marking!r} is not one of {', '.join(MARKINGS)}")
    if not 0.0 < theta <= 1.0:
        raise ValueError(f"theta={theta!r} is not in (0, 1]")


def mark(indicators: np.ndarray, marking: str, theta: float) -> np.ndarray:
    check_marking(marking, theta)
    if not np.isfinite(indicators).all():
        raise ValueError("cannot mark: the indicators contain NaN or inf")
    return doerfler(indicators, theta) if marking == "doerfler" else maximum(indicators, theta)


def grade_contact_trace(marked: np.ndarray, length: np.ndarray, element: np.ndarray,
                        coordinate: np.ndarray, n_elements: int, ratio: float = 2.0) -> np.ndarray:
    """Add to ``marked`` the elements of contact facets that would otherwise be more than
    ``ratio`` times longer than a neighbouring contact facet after refinement (a 2:1 grading
    closure along Gamma_C; facets in trace order, ``coordinate`` (2, n) their end points).

    Why: a multiplier segment must be at least twice its longest facet (h/H <= 1/2), so an
    unrefined long facet next to a refined contact zone forces a long segment over it, and the
    estimator never marks that facet (nothing is wrong there): the mixed method's multiplier
    mesh would lag the refinement (seen on the Hertz scene). Refining such facets is cheap and
    harmless for every formulation."""
    flagged = np.zeros(n_elements, dtype=bool)
    flagged[marked] = True
    joined = np.isclose(coordinate[1, :-1], coordinate[0, 1:])  # neighbours really touch
    while True:
        after = np.where(flagged[element], 0.5 * length, length)
        left = np.where(np.r_[False, joined], np.r_[np.inf, after[:-1]], np.inf)
        right = np.where(np.r_[joined, False], np.r_[after[1:], np.inf], np.inf)
        too_long = (after > ratio * np.minimum(left, right) * (1 + 1e-9)) & ~flagged[element]
        if not too_long.any():
            return np.flatnonzero(flagged)
        flagged[element[too_long]] = True

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



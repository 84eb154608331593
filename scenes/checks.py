"""What every scene module checks its parameters with: the error type and the number tests."""

from __future__ import annotations

import numbers
from collections.abc import Callable

import numpy as np

PointFunction = Callable[[np.ndarray], np.ndarray]
"""A function of points ``x`` with shape (d, ...) (d = 2 or 3) returning values of shape (...)
or (d, ...)."""


class SceneError(ValueError):
    """A scene parameter is out of its allowed range."""


def is_number(value) -> bool:
    """A real number as users write them: Python or numpy ints and floats, never a bool."""
    return isinstance(value, numbers.Real) and not isinstance(value, bool | np.bool_)


def is_integer(value) -> bool:
    """An integer (Python or numpy), never a bool."""
    return isinstance(value, numbers.Integral) and not isinstance(value, bool | np.bool_)

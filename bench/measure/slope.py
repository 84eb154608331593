"""The suite's one slope fit (docs/report.md, "Slopes and their intervals"): least squares of
log y against log x, with the slope's standard error and its 95 % confidence interval from
Student's t with n - 2 degrees of freedom. Two points give a slope without an interval (the
interval is infinite), so a verdict that needs the interval calls such a fit too coarse."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import stats

CONFIDENCE = 0.95


@dataclass(frozen=True)
class SlopeFit:
    """A fitted slope with its interval; ``points``: how many (x, y) pairs it used."""

    slope: float
    stderr: float
    low: float
    high: float
    points: int

    @property
    def width(self) -> float:
        return self.high - self.low

    def meets(self, low: float, high: float) -> bool:
        """Whether the interval has a point in [low, high]."""
        return bool(self.low <= high and self.high >= low)

    def text(self) -> str:
        """'-0.497 [-0.512, -0.482]', or the slope alone without an interval."""
        if not math.isfinite(self.slope):
            return ""
        if not math.isfinite(self.width):
            return f"{self.slope:.3g}"
        return f"{self.slope:.3g} [{self.low:.3g}, {self.high:.3g}]"


NO_FIT = SlopeFit(math.nan, math.nan, math.nan, math.nan, 0)


def fit_slope(x, y) -> SlopeFit:
    """The slope of log y over log x with its 95 % interval; pairs with x <= 0 or y <= 0 or
    not finite are left out; fewer than two pairs give ``NO_FIT``."""
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    keep = np.isfinite(x) & np.isfinite(y) & (x > 0) & (y > 0)
    lx, ly = np.log(x[keep]), np.log(y[keep])
    n = lx.size
    if n < 2 or np.ptp(lx) == 0:
        return NO_FIT
    slope, intercept = np.polyfit(lx, ly, 1)
    if n == 2:
        return SlopeFit(float(slope), math.inf, -math.inf, math.inf, 2)
    residual = ly - (slope * lx + intercept)
    stderr = math.sqrt(float(residual @ residual) / (n - 2) / float(((lx - lx.mean()) ** 2).sum()))
    half = float(stats.t.ppf(0.5 + CONFIDENCE / 2, n - 2)) * stderr
    return SlopeFit(float(slope), stderr, float(slope) - half, float(slope) + half, n)

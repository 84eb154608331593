"""The suite's one slope fit (bench.measure.slope): slope, standard error and 95 % interval."""

import math

import numpy as np
from scipy import stats

from bench.measure.slope import fit_slope


def test_a_power_law_gives_its_exponent_with_a_zero_width_interval():
    n = np.array([1e3, 2e3, 4e3, 8e3, 1.6e4])
    fit = fit_slope(n, 3.0 * n**-0.5)
    assert abs(fit.slope + 0.5) <= 1e-12  # exact data: round-off only
    assert fit.width <= 1e-10 and fit.points == 5


def test_the_interval_is_students_t_times_the_standard_error():
    """Known residuals: log y = -0.5 log x + (+d, -d, +d, -d) at log x = 0, 1, 2, 3. The
    slope's standard error from the textbook formula, computed here independently."""
    lx = np.arange(4.0)
    d = 0.01
    ly = -0.5 * lx + np.array([d, -d, d, -d])
    fit = fit_slope(np.exp(lx), np.exp(ly))
    slope, intercept = np.polyfit(lx, ly, 1)
    residual = ly - slope * lx - intercept
    stderr = math.sqrt((residual**2).sum() / 2 / ((lx - lx.mean()) ** 2).sum())
    assert abs(fit.stderr - stderr) <= 1e-12
    half = stats.t.ppf(0.975, 2) * stderr  # 4.303 for 2 degrees of freedom
    assert abs(fit.high - fit.low - 2 * half) <= 1e-12
    assert fit.meets(fit.slope, fit.slope) and not fit.meets(fit.high + 0.01, 1.0)


def test_two_points_give_a_slope_without_an_interval_and_bad_points_are_left_out():
    fit = fit_slope([1e3, 4e3, -1.0, 5e3], [1.0, 0.5, 2.0, np.nan])
    assert abs(fit.slope + 0.5) <= 1e-12 and math.isinf(fit.width) and fit.points == 2
    assert math.isnan(fit_slope([1e3], [1.0]).slope)
    assert fit_slope([1e3, 1e3, 1e3], [1.0, 2.0, 3.0]).points == 0  # no spread in x

"""The rates table's price of ``--target-error`` against an oracle (bench/matrix/rates.py)."""

import numpy as np
import pandas as pd

from bench.matrix.rates import target_dofs_ratio


def sequence(effectivity: float, rate: float = -0.5) -> pd.DataFrame:
    n = np.array([1e3, 1.8e3, 3.5e3, 6e3, 1.1e4, 2e4])
    error = 3.0 * n**rate
    return pd.DataFrame({"ndofs": n, "energy_error": error, "eta": effectivity * error})


def test_a_constant_effectivity_costs_its_power_of_the_rate():
    """error = C N^r and eta = c error: the error reaches eta_l at N_l c^(1/r), so the ratio is
    c^(-1/r) on every level (1.2^2 = 1.44 at r = -1/2, 1.2^4 at r = -1/4); log-log
    interpolation of a power law is exact (round-off only)."""
    for rate in (-0.5, -0.25):
        rows = sequence(1.2, rate)
        expected = 1.2 ** (-1 / rate)
        assert abs(target_dofs_ratio(rows, rows.tail(4)) - expected) <= 1e-12 * expected


def test_an_estimate_below_the_error_that_it_never_reaches_gives_nan():
    rows = sequence(0.8)
    assert np.isnan(target_dofs_ratio(rows, rows.tail(1)))
    # below the error of its own level but above a finer one's: less than 1 (0.8^2 = 0.64)
    assert abs(target_dofs_ratio(rows, rows.iloc[[2]]) - 0.64) <= 1e-12


def test_the_largest_ratio_of_the_window_is_reported():
    rows = sequence(1.2)
    rows.loc[4, "eta"] = 1.5 * rows.loc[4, "energy_error"]
    assert abs(target_dofs_ratio(rows, rows.tail(4)) - 1.5**2) <= 1e-12

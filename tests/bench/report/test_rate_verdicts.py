"""Rate verdicts say only what the levels can show: none from a short or coarse fit, never
'agrees' for an error that grows, nor for a row whose pressure error grows."""

import numpy as np

from bench.report.tables import MIN_VERDICT_DOFS, _verdict


def test_a_slope_within_the_tolerance_from_enough_fine_levels_agrees():
    assert _verdict(-0.48, -0.5, 6, 20000) == "agrees"
    assert _verdict(-0.3, -0.5, 6, 20000) == "shallower than claimed"


def test_no_verdict_from_three_levels_or_under_the_dof_count():
    assert _verdict(-0.5, -0.5, 3, 20000).startswith("too coarse to judge (3 levels")
    assert _verdict(-0.5, -0.5, 6, MIN_VERDICT_DOFS - 1).startswith("too coarse to judge")


def test_a_growing_error_never_agrees():
    assert _verdict(0.05, 0.0, 6, 20000) == "error grows"  # within 0.1 of 0, but growing
    with_pressure = _verdict(-0.5, -0.5, 6, 20000, pressure_rate=0.78)
    assert with_pressure != "agrees" and "pressure error grows (slope +0.78)" in with_pressure
    assert _verdict(np.nan, -0.5) == "not measured"

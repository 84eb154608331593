"""Rate verdicts read the slope's 95 % interval: "agrees" only where it meets the claim (+-
0.05), "too coarse to judge" from a short or coarse fit or an interval wider than 0.1, never
"agrees" for an error that grows; the report's counts and the gates read the same verdicts."""

import numpy as np
import pandas as pd

from bench.measure.slope import SlopeFit
from bench.report.questions import rate_question
from bench.report.tables import MIN_VERDICT_DOFS, rate_verdict
from bench.verify.gates import gate_passes


def fit(low: float, high: float) -> SlopeFit:
    return SlopeFit((low + high) / 2, np.nan, low, high, 6)


def test_an_interval_that_meets_the_claim_agrees_and_one_beyond_it_does_not():
    assert rate_verdict(fit(-0.56, -0.50), -0.5, 6, 20000) == "agrees"
    assert rate_verdict(fit(-0.58, -0.56), -0.5, 6, 20000) == "steeper than claimed"
    assert rate_verdict(fit(-0.32, -0.28), -0.5, 6, 20000) == "shallower than claimed"


def test_no_verdict_from_few_or_coarse_levels_or_a_wide_interval():
    assert rate_verdict(fit(-0.52, -0.48), -0.5, 3, 20000) == "too coarse to judge"
    assert rate_verdict(fit(-0.52, -0.48), -0.5, 6, MIN_VERDICT_DOFS - 1) == \
        "too coarse to judge"
    assert rate_verdict(fit(-0.56, -0.44), -0.5, 6, 20000) == "too coarse to judge"  # 0.12
    two_points = SlopeFit(-0.5, np.inf, -np.inf, np.inf, 2)
    assert rate_verdict(two_points, -0.5, 6, 20000) == "too coarse to judge"


def test_a_growing_error_never_agrees_and_nothing_measured_says_so():
    assert rate_verdict(fit(0.01, 0.04), 0.0, 6, 20000) == "error grows"
    assert rate_verdict(SlopeFit(np.nan, np.nan, np.nan, np.nan, 0), -0.5) == "not measured"


def test_the_question_counts_the_same_verdicts_the_table_shows():
    rates = pd.DataFrame({"scene": ["paper"] * 3, "strategy": ["adaptive"] * 3,
                          "verdict": ["agrees", "steeper than claimed", "too coarse to judge"]})
    answer = rate_question(rates).answer
    assert answer.startswith("1 of 2 judged slopes agree") and "1 are too coarse" in answer


def test_a_slope_gate_passes_where_its_interval_meets_the_band():
    row = pd.Series({"error_rate": -0.46, "error_rate_low": -0.49, "error_rate_high": -0.43})
    assert gate_passes(row, "error_rate", -0.6, -0.48)  # the interval reaches -0.49
    assert not gate_passes(row, "error_rate", -0.6, -0.5)
    assert gate_passes(pd.Series({"effectivity_min": 1.2}), "effectivity_min", 1.0, 2.0)

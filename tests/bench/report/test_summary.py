"""The first screen's 'fastest' column: worked by hand on a two-sequence table."""

import numpy as np
import pandas as pd
import pytest

from bench.report.summary import fastest
from bench.sequence.rows import COLUMNS, PHASE_TIMES


def sequence(formulation, errors, seconds_per_level):
    rows = []
    for level, error in enumerate(errors):
        row = {c: np.nan for c in COLUMNS} | dict(
            scene="s", formulation=formulation, solver="active-set", estimator="residual",
            strategy="adaptive", order=1, level=level, ndofs=100 * 2**level, status="ok",
            energy_error=error, eta=2 * error, scene_parameters="", formulation_options="")
        row.update({phase: 0.0 for phase in PHASE_TIMES})
        row[PHASE_TIMES[0]] = seconds_per_level
        rows.append(row)
    return rows


def test_the_fastest_reaches_the_median_final_error_first():
    table = pd.DataFrame(sequence("fast", [1.0, 0.1, 0.01], 1.0)
                         + sequence("slow", [1.0, 0.5, 0.02], 0.5))
    best = fastest(table)
    # finals 0.01 and 0.02: median 0.015, two digits rounded up: 0.015
    assert best["target"] == pytest.approx(0.015, rel=1e-12)
    # only "fast" reaches it, at level 2 after 3 levels of 1 s
    assert best["ranking"] == [{"combination": "fast/active-set/residual/adaptive", "order": 1,
                                "ndofs": 400, "seconds": 3.0}]
    assert best["compared"] == 2 and best["column"] == "energy_error"


def test_without_a_truth_eta_is_the_measure():
    table = pd.DataFrame(sequence("a", [1.0, 0.1], 1.0))
    table["energy_error"] = np.nan
    assert fastest(table)["column"] == "eta"

"""The verdict box, worked by hand on small tables: the cheapest combinations to a relative
error and their ties, the timing noise measured from identical work, the sharpest estimator and
the guaranteed one's range."""

import numpy as np
import pandas as pd
import pytest

from bench.report.verdict import (
    TimingNoise,
    cheapest,
    guaranteed_text,
    sharpest_text,
    timing_noise,
)
from bench.sequence.rows import COLUMNS, PHASE_TIMES


def sequence(formulation, errors, seconds_per_level, estimator="residual",
             strategy="adaptive", effectivity=None):
    rows = []
    for level, error in enumerate(errors):
        row = {c: np.nan for c in COLUMNS} | dict(
            scene="s", formulation=formulation, solver="active-set", estimator=estimator,
            strategy=strategy, order=1, cell="tri", level=level, ndofs=1000 * 2**level,
            status="ok", energy_error=error, eta=2 * error, scene_parameters="",
            formulation_options="", reference_too_coarse=False,
            effectivity_index=(effectivity or [2.0] * len(errors))[level])
        row.update({phase: 0.0 for phase in PHASE_TIMES})
        row[PHASE_TIMES[0]] = seconds_per_level
        rows.append(row)
    return rows


def test_the_cheapest_first_reaches_the_relative_error_and_near_times_tie():
    table = pd.DataFrame(sequence("fast", [1.0, 0.1, 0.01], 1.0)
                         + sequence("slow", [1.0, 0.5, 0.02], 0.5)
                         + sequence("close", [1.0, 0.05], 1.6))
    # with ||u|| = 10 the target 1e-2 is an error of 0.1: "slow" reaches it at level 2 after
    # 3 x 0.5 = 1.5 s, "fast" at level 1 after 2 x 1 = 2 s, "close" at level 1 after 3.2 s
    best = cheapest(pd.DataFrame(table), 10.0, 1e-2, None)
    assert [(r["combination"], r["seconds"]) for r in best["ranking"]] == [
        ("slow/active-set/residual/adaptive P1", 1.5),
        ("fast/active-set/residual/adaptive P1", 2.0),
        ("close/active-set/residual/adaptive P1", 3.2)]
    assert best["ties"] == 0 and best["compared"] == 3
    # a noise of 0.1 s + 40 % around 1.5 s is 0.7 s: 2.0 s ties, 3.2 s does not
    assert cheapest(table, 10.0, 1e-2, TimingNoise(0.1, 0.4, 1))["ties"] == 1


def test_a_row_whose_reference_is_too_coarse_reaches_nothing():
    table = pd.DataFrame(sequence("a", [1.0, 0.01], 1.0))
    table.loc[1, "reference_too_coarse"] = True
    assert cheapest(table, 1.0, 1e-1, None)["ranking"] == []


def test_timing_noise_is_the_spread_of_identical_uniform_work():
    # two estimators on the same uniform sequence: level times 0.05/0.06 s (short) and then
    # 1.0/1.2 s, cumulative 0.05/0.06 and 1.05/1.26
    table = pd.DataFrame(sequence("vi", [1.0, 0.5], 0.05, "residual", "uniform")
                         + sequence("vi", [1.0, 0.5], 0.06, "averaging", "uniform"))
    table.loc[[1, 3], PHASE_TIMES[0]] = [1.0, 1.2]
    noise = timing_noise(table)
    assert noise.samples == 2
    assert noise.absolute == pytest.approx(0.01, rel=1e-9)  # 0.06 - 0.05 (one short level)
    assert noise.relative == pytest.approx(0.21 / 1.05, rel=1e-9)  # (1.26 - 1.05) / 1.05
    alone = pd.DataFrame(sequence("vi", [1.0, 0.5], 0.05, "residual", "uniform"))
    assert timing_noise(alone) is None  # no twin: nothing measured


def test_the_sharpest_estimator_is_the_one_nearest_one_and_counts_its_misses():
    table = pd.DataFrame(sequence("vi", [1.0, 0.5, 0.2], 1.0, "averaging",
                                  effectivity=[0.9, 1.1, 0.95])
                         + sequence("vi", [1.0, 0.5, 0.2], 1.0, "residual",
                                    effectivity=[3.0, 3.5, 4.0]))
    assert sharpest_text(table) == ("averaging: 0.9..1.1, below the error on 2 of 3 levels "
                                    "(67 %)")


def test_the_guaranteed_range_names_the_combination_at_each_end():
    table = pd.DataFrame(sequence("vi", [1.0, 0.5], 1.0, "equilibrated",
                                  effectivity=[1.4, 1.2])
                         + sequence("mixed", [1.0, 0.5], 1.0, "equilibrated", "uniform",
                                    effectivity=[2.5, 1.9]))
    assert guaranteed_text(table) == (
        "equilibrated: 1.2 (vi/active-set/adaptive P1, 2000 DOFs) .. "
        "2.5 (mixed/active-set/uniform P1, 1000 DOFs)")
    table.loc[1, "effectivity_index"] = 0.99
    assert guaranteed_text(table).endswith("BELOW 1: the bound failed")

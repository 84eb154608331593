"""The recommendation and its evidence, worked by hand on small tables: the cheapest
combinations to a relative error, their ties from the repeated timings, the bound to stop on
and what the heuristic estimators cost."""

import numpy as np
import pandas as pd

from bench.report.ranking import rank, spread_text
from bench.report.verdict import (
    estimator_records,
    heuristic_text,
    recommendation,
    stop_on,
    stop_text,
)
from bench.sequence.rows import COLUMNS, PHASE_TIMES


def sequence(formulation, errors, seconds_per_level, estimator="residual",
             strategy="adaptive", effectivity=None, order=1):
    rows = []
    key = f"{formulation}-{estimator}-{strategy}-{order}"
    for level, error in enumerate(errors):
        row = {c: np.nan for c in COLUMNS} | dict(
            scene="s", formulation=formulation, solver="active-set", estimator=estimator,
            strategy=strategy, order=order, cell="tri", level=level, ndofs=1000 * 2**level,
            status="ok", energy_error=error, eta=2 * error, scene_parameters="",
            formulation_options="", reference_too_coarse=False, sequence_key=key,
            effectivity_index=(effectivity or [2.0] * len(errors))[level])
        row.update({phase: 0.0 for phase in PHASE_TIMES})
        row[PHASE_TIMES[0]] = seconds_per_level
        rows.append(row)
    return rows


def timings(samples: dict) -> pd.DataFrame:
    """Repeated samples: {(key, level): [seconds, ...]}."""
    return pd.DataFrame([{"sequence_key": key, "level": level, "sample": k + 1, "seconds": s}
                         for (key, level), values in samples.items()
                         for k, s in enumerate(values)])


def three() -> pd.DataFrame:
    # with ||u|| = 10 the target 1e-2 is an error of 0.1: "slow" reaches it at level 2 after
    # 3 x 0.5 = 1.5 s, "fast" at level 1 after 2 x 1 = 2 s, "close" at level 1 after 3.2 s
    return pd.DataFrame(sequence("fast", [1.0, 0.1, 0.01], 1.0)
                        + sequence("slow", [1.0, 0.5, 0.02], 0.5)
                        + sequence("close", [1.0, 0.05], 1.6))


def test_without_repeats_the_single_times_rank_and_nothing_ties():
    ranking = rank(three(), 10.0, 1e-2, None)
    assert [(r.combination, r.seconds, r.samples) for r in ranking.ranked] == [
        ("slow/active-set/residual/adaptive P1", 1.5, 1),
        ("fast/active-set/residual/adaptive P1", 2.0, 1),
        ("close/active-set/residual/adaptive P1", 3.2, 1)]
    assert ranking.ties == 0 and ranking.compared == 3
    assert "measured once" in spread_text(None)


def test_repeats_rank_by_their_best_and_ties_fall_within_the_two_best():
    samples = timings({("slow-residual-adaptive-1", 2): [1.9, 2.0, 2.6],
                       ("fast-residual-adaptive-1", 1): [1.8, 1.95, 2.1],
                       ("close-residual-adaptive-1", 1): [2.2, 3.0, 3.1]})
    ranking = rank(three(), 10.0, 1e-2, samples)
    # best 1.8 (fast), 1.9 (slow), 2.2 (close); fast's two best are 1.8 and 1.95: slow's
    # best 1.9 lies within (a tie), close's 2.2 does not
    assert [r.combination.split("/")[0] for r in ranking.ranked] == ["fast", "slow", "close"]
    assert (ranking.ranked[0].seconds, ranking.ranked[0].high) == (1.8, 1.95)
    assert ranking.ties == 1
    # second best over best: 0.15 / 1.8 = 8.3 %, 0.1 / 1.9 = 5.3 %, 0.8 / 2.2 = 36 %
    assert "8.3 % above the best in the median (36 % at most)" in spread_text(samples)


def test_a_combination_timed_once_ranks_after_the_timed_ones_and_never_ties():
    samples = timings({("fast-residual-adaptive-1", 1): [1.8, 1.9, 2.0]})
    ranking = rank(three(), 10.0, 1e-2, samples)
    # slow's single 1.5 s (the matrix's) is not comparable with repeated samples
    assert [r.combination.split("/")[0] for r in ranking.ranked] == ["fast", "slow", "close"]
    assert ranking.ties == 0 and ranking.ranked[1].samples == 1


def test_a_row_whose_reference_is_too_coarse_reaches_nothing():
    table = pd.DataFrame(sequence("a", [1.0, 0.01], 1.0))
    table.loc[1, "reference_too_coarse"] = True
    assert rank(table, 1.0, 1e-1, None).ranked == ()


def test_the_bound_to_stop_on_is_the_sharpest_that_never_fell_below():
    table = pd.DataFrame(
        sequence("vi", [1.0, 0.5, 0.2], 1.0, "averaging", effectivity=[0.9, 1.1, 0.95])
        + sequence("vi", [1.0, 0.5, 0.2], 1.0, "residual", effectivity=[3.0, 3.5, 4.0])
        + sequence("vi", [1.0, 0.5, 0.2], 1.0, "equilibrated", effectivity=[1.2, 1.3, 1.4])
        + sequence("mixed", [1.0, 0.5, 0.2], 1.0, "equilibrated-local",
                   effectivity=[1.1, 1.15, 1.2]))
    records = estimator_records(table)
    assert stop_on(records).name == "equilibrated-local"  # median 1.15 < 1.3
    assert stop_text(records) == "equilibrated-local 1.1..1.2, never below the error"
    assert heuristic_text(records) == ("averaging: below on 2 of 3 levels, up to 1.1 x the "
                                       "error; residual: below on 0 of 3 levels, up to 4 x "
                                       "the error")
    table.loc[(table["estimator"] == "equilibrated-local") & (table["level"] == 2),
              "effectivity_index"] = 0.99
    assert stop_on(estimator_records(table)).name == "equilibrated"


def test_the_recommendation_names_the_cheapest_to_the_finest_target_reached():
    table = pd.DataFrame(sequence("vi", [1.0, 0.09, 0.009], 1.0, order=3)
                         + sequence("mixed", [1.0, 0.5, 0.08], 0.2, order=2)
                         + sequence("vi", [1.0, 0.5, 0.2, 0.1], 1.0, "equilibrated",
                                    effectivity=[1.2, 1.3, 1.4, 1.5]))
    rankings = [rank(table, 10.0, t, None) for t in (1e-2, 1e-3)]
    # 1e-2 (error 0.1): mixed P2 after 0.6 s, vi P3 after 2 s; 1e-3 (0.01): vi P3 only
    assert rankings[0].ranked[0].combination.startswith("mixed")
    sentence = recommendation("s", rankings, estimator_records(table))
    assert sentence == ("s: use vi adaptive P3 steered by residual: 0.01 in 2 s (2000 DOFs), "
                        "0.001 in 3 s (4000 DOFs); stop on equilibrated (effectivity 1.2..1.5, "
                        "never below the error).")

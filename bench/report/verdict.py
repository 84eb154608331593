"""The report's answer per scene (docs/report.md, "The recommendation"): one sentence (the
combination to use, the estimator to steer with and the bound to stop on), then its evidence:
the cheapest combinations to each relative energy-norm error the run reached
(``bench.report.ranking``), the guaranteed bound's effectivity and safety, and what the
heuristic estimators would have cost."""

from __future__ import annotations

from dataclasses import dataclass

import pandas as pd

from bench.matrix.cost import RELATIVE_TARGETS
from bench.matrix.rates import judged_levels
from bench.report.ranking import Ranking, rank, ranking_text, sig3
from estimators import guaranteed_estimators

MAIN_TARGET = RELATIVE_TARGETS[0]
EFFECTIVITY_FROM_DOFS = 1000  # coarse levels are pre-asymptotic for every estimator


def late_judged(group: pd.DataFrame) -> pd.DataFrame:
    """The judged levels from EFFECTIVITY_FROM_DOFS DOFs (all judged levels where none is)."""
    judged = judged_levels(group)
    fine = judged[judged["ndofs"] >= EFFECTIVITY_FROM_DOFS]
    return fine if len(fine) else judged


@dataclass(frozen=True)
class EstimatorRecord:
    """An estimator's effectivity on one scene's judged levels from EFFECTIVITY_FROM_DOFS."""

    name: str
    guaranteed: bool
    low: float
    median: float
    high: float
    levels: int
    below: int  # levels with eta < error

    def text(self) -> str:
        below = ("never below the error" if not self.below else
                 f"below the error on {self.below} of {self.levels} levels "
                 f"({100 * self.below / self.levels:.0f} %)")
        return f"{self.name} {sig3(self.low)}..{sig3(self.high)}, {below}"


def estimator_records(group: pd.DataFrame) -> list[EstimatorRecord]:
    judged, safe = late_judged(group), set(guaranteed_estimators())
    out = []
    for name, rows in judged.groupby("estimator", sort=True):
        eff = rows["effectivity_index"]
        out.append(EstimatorRecord(str(name), name in safe, float(eff.min()),
                                   float(eff.median()), float(eff.max()), len(eff),
                                   int((eff < 1).sum())))
    return out


def stop_on(records: list[EstimatorRecord]) -> EstimatorRecord | None:
    """The sharpest guaranteed bound that never fell below the error (smallest median
    effectivity); None where none was run or every one fell below."""
    safe = [r for r in records if r.guaranteed and r.below == 0]
    return min(safe, key=lambda r: r.median) if safe else None


def stop_text(records: list[EstimatorRecord]) -> str:
    best = stop_on(records)
    if best is not None:
        return best.text()
    failed = [r.text() for r in records if r.guaranteed]
    return ("no guaranteed bound stayed above the error: " + "; ".join(failed) if failed
            else "no guaranteed bound was run")


def heuristic_text(records: list[EstimatorRecord]) -> str:
    """How often each estimator without a guarantee fell below the error, how far above."""
    return "; ".join(f"{r.name}: below on {r.below} of {r.levels} levels, up to "
                     f"{sig3(r.high)} x the error" for r in records if not r.guaranteed) or "none"


@dataclass(frozen=True)
class SceneAnswer:
    scene: str
    norm: float | None  # ||u||, the scale of relative errors
    sentence: str
    rankings: tuple[Ranking, ...]
    records: tuple[EstimatorRecord, ...]


def recommendation(scene: str, rankings: list[Ranking],
                   records: list[EstimatorRecord]) -> str:
    """One sentence: the cheapest combination to the finest target reached, its time to every
    reached target, and the bound to stop on."""
    reached = [r for r in rankings if r.ranked]
    if not reached:
        return f"{scene}: no combination reached a relative error of {sig3(MAIN_TARGET)}."
    best = reached[-1].ranked[0]
    name, _, rest = best.combination.partition("/")
    solver, estimator, strategy_order = rest.split("/", 2)
    times = ", ".join(f"{sig3(r.target)} in {sig3(t.seconds)} s ({t.ndofs} DOFs)"
                      for r in reached for t in r.ranked if t.combination == best.combination)
    tied = (f" ({reached[-1].ties} more tie with it)" if reached[-1].ties else "")
    safe = stop_on(records)
    stop = (f"stop on {safe.name} (effectivity {sig3(safe.low)}..{sig3(safe.high)}, never "
            "below the error)" if safe else "no guaranteed bound stayed above the error")
    return (f"{scene}: use {name} {strategy_order} steered by {estimator}{tied}: {times}; "
            f"{stop}.")


def scene_answer(scene: str, group: pd.DataFrame, norm: float | None,
                 timings: pd.DataFrame | None) -> SceneAnswer:
    rankings = [rank(group, norm, t, timings) for t in RELATIVE_TARGETS] if norm else []
    records = estimator_records(group)
    sentence = (recommendation(scene, rankings, records) if norm
                else f"{scene}: no truth, errors not measured.")
    return SceneAnswer(scene, norm, sentence, tuple(rankings), tuple(records))


def evidence_row(answer: SceneAnswer) -> dict:
    """One row of the evidence table under the recommendations."""
    row = {"scene": answer.scene}
    for ranking in answer.rankings:
        row[f"cheapest to {sig3(ranking.target)}"] = ranking_text(ranking)
    row[f"stop on (from {EFFECTIVITY_FROM_DOFS} DOFs)"] = stop_text(list(answer.records))
    row["heuristic estimators"] = heuristic_text(list(answer.records))
    return row

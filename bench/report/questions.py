"""The questions a user brings to the report (docs/report.md, "Questions you may bring"), each
answered in a sentence from the run's numbers, with at most one small table, and a link to the
section with the details."""

from __future__ import annotations

from dataclasses import dataclass, field

import pandas as pd

from estimators import guaranteed_estimators


@dataclass(frozen=True)
class Question:
    question: str
    answer: str
    link: str  # the id of the section with the details
    link_text: str
    table: pd.DataFrame = field(default_factory=pd.DataFrame)


def _below(text: str) -> int:
    """The count in an estimator summary's 'levels with eta < error' cell ('3 (8 %)')."""
    return int(str(text).split()[0]) if str(text).strip() else 0


def estimator_question(estimators: pd.DataFrame) -> Question:
    if estimators.empty:
        answer = "No level had a truth sharp enough to judge an estimator."
    else:
        never = estimators[estimators["levels with eta < error"].map(_below) == 0]["estimator"]
        guaranteed = [g for g in guaranteed_estimators() if g in set(estimators["estimator"])]
        answer = ("Never below the error on a judged level: "
                  + (", ".join(never) if len(never) else "none")
                  + "; a guaranteed bound by construction: "
                  + (", ".join(guaranteed) if guaranteed else "none run")
                  + ". Steer with the sharpest (median nearest 1), stop on a safe one.")
    return Question("Which estimator can steer my refinement, and which can I stop on?",
                    answer, "estimators", "estimators: the full comparison and figure",
                    estimators)


def rate_question(rates: pd.DataFrame) -> Question:
    claimed = rates[rates["verdict"] != ""] if "verdict" in rates else rates.iloc[:0]
    if claimed.empty:
        return Question("Do the seed paper's rates hold?", "No claimed rate was measured.",
                        "rates", "rates")
    kind = claimed["verdict"]
    counts = pd.crosstab([claimed["scene"], claimed["strategy"]], kind).reset_index()
    judged = kind[kind != "too coarse to judge"]
    answer = (f"{int((judged == 'agrees').sum())} of {len(judged)} judged slopes agree with "
              "the claimed one (their 95 % interval meets it); "
              f"{int((kind == 'too coarse to judge').sum())} are too coarse to judge (too few "
              "or too coarse levels, or an interval wider than 0.1).")
    return Question("Do the seed paper's rates hold?", answer, "rates",
                    "rates: every slope beside its claim", counts)


def solver_question(agreement: pd.DataFrame) -> Question:
    if agreement.empty:
        answer = "No level was cross-checked against the reference solver."
    else:
        worst = pd.to_numeric(agreement["max rel. energy-norm difference"],
                              errors="coerce").max()
        answer = (f"Over {int(agreement['levels'].sum())} cross-checked levels the largest "
                  f"relative energy-norm difference to the reference solver is {worst:.1e}.")
    return Question("Does the fast solver give the reference solver's answer?", answer,
                    "agreement", "agreement per scene and formulation")


def hard_question(hard_verdicts: str) -> Question:
    return Question("Where do the methods break?",
                    (hard_verdicts[0].upper() + hard_verdicts[1:] + ".") if hard_verdicts
                    else "The hard cases were not run for these results.",
                    "hard-cases", "the verdict matrix of every hard case")


def questions(tables: dict, hard_verdicts: str, orders: list) -> list[Question]:
    """The questions in the order a user asks them."""
    cost = Question("Which combination reaches my accuracy at the least cost?",
                    "The verdict box above, per scene; each scene's section ranks the five "
                    "cheapest to each relative error and plots error against time.",
                    "results-per-scene", "results per scene")
    found = [estimator_question(tables["estimators"]), cost,
             rate_question(tables["rates"]), solver_question(tables["agreement"]),
             hard_question(hard_verdicts)]
    if orders:
        found.append(Question("What does a higher polynomial order buy?",
                              "Per exact scene, the order that first reaches a relative "
                              "error of 1e-3, and at what cost.", "orders",
                              "polynomial order"))
    return found

"""The report's first screen: one recommendation per scene (``bench.report.verdict``), then its
evidence table, the verdicts on the seed paper's claimed rates, and any failure or flag."""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from bench.matrix.cost import read_timings
from bench.report.ranking import sig3, spread_text
from bench.report.verdict import SceneAnswer, evidence_row, scene_answer
from bench.truth.norms import scene_norm
from formulations import STATUS_FAILED


def claim_verdicts(rates: pd.DataFrame, scene: str) -> str:
    """'k of n agree' over the rate verdicts of ``scene`` that have a claimed slope."""
    if rates.empty or "verdict" not in rates:
        return "no claim"
    mine = rates[(rates["scene"] == scene) & (rates["verdict"] != "")]
    if mine.empty:
        return "no claim"
    coarse = mine["verdict"].str.startswith("too coarse")
    judged = mine[~coarse]
    agree = int((judged["verdict"] == "agrees").sum())
    text = f"{agree} of {len(judged)} judged slopes agree"
    return text + (f" ({int(coarse.sum())} too coarse to judge)" if coarse.any() else "")


def flags(everything: pd.DataFrame) -> str:
    failed = everything[everything["status"] == STATUS_FAILED]
    coarse = int(everything["reference_too_coarse"].fillna(False).astype(bool).sum())
    skipped = int((everything["status"] == "skipped").sum())
    parts = [f"{len(failed)} failed" if len(failed) else "",
             f"{coarse} rows with a too coarse reference" if coarse else "",
             f"{skipped} skipped" if skipped else ""]
    return ", ".join(p for p in parts if p) or "none"


def scene_answers(rows: pd.DataFrame, truth: dict, results: Path | None,
                  timings: pd.DataFrame | None = None) -> list[SceneAnswer]:
    """Every scene's answer, its cost from the results folder's timings when there are any
    (``timings``: already read)."""
    timings = read_timings(results) if timings is None else timings
    return [scene_answer(str(scene), group, scene_norm(str(scene), truth), timings)
            for scene, group in rows.groupby("scene", sort=True)]


def first_screen(everything: pd.DataFrame, rows: pd.DataFrame, rates: pd.DataFrame,
                 truth: dict, results: Path | None = None) -> dict:
    """The recommendations, the evidence table (one row per scene), how cost was measured,
    and per scene the five cheapest combinations to each relative error (the detail)."""
    timings = read_timings(results)
    answers = scene_answers(rows, truth, results, timings)
    table, detail = [], []
    for answer in answers:
        table.append({**evidence_row(answer),
                      "seed paper's rates": claim_verdicts(rates, answer.scene),
                      "failures and flags":
                      flags(everything[everything["scene"] == answer.scene])})
        for ranking in answer.rankings:
            if ranking.ranked:
                detail.append({"scene": answer.scene, "target": sig3(ranking.target),
                               "norm": sig3(answer.norm), "ranking": ranking.frame()})
    return {"sentences": [a.sentence for a in answers], "table": pd.DataFrame(table),
            "detail": detail, "noise": spread_text(timings)}

"""The report's first screen: the verdict box per scene (``bench.report.verdict``), the
verdicts on the seed paper's claimed rates, and any failure or flag."""

from __future__ import annotations

import pandas as pd

from bench.report.norms import scene_norm
from bench.report.verdict import (
    cheapest,
    noise_text,
    shown_targets,
    sig3,
    timing_noise,
    verdict_row,
)
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
    text = f"{agree} of {len(judged)} slopes agree"
    return text + (f" ({int(coarse.sum())} too coarse to judge)" if coarse.any() else "")


def flags(everything: pd.DataFrame) -> str:
    failed = everything[everything["status"] == STATUS_FAILED]
    coarse = int(everything["reference_too_coarse"].fillna(False).astype(bool).sum())
    skipped = int((everything["status"] == "skipped").sum())
    parts = [f"{len(failed)} failed" if len(failed) else "",
             f"{coarse} rows with a too coarse reference" if coarse else "",
             f"{skipped} skipped" if skipped else ""]
    return ", ".join(p for p in parts if p) or "none"


def first_screen(everything: pd.DataFrame, rows: pd.DataFrame, rates: pd.DataFrame,
                 truth: dict) -> dict:
    """The verdict box (one row per scene, ``bench.report.verdict``), the timing noise its ties
    use, and per scene the cheapest combinations to each relative error (the detail)."""
    noise = timing_noise(rows)
    norms = {scene: scene_norm(scene, truth) for scene in rows["scene"].unique()}
    targets = shown_targets(rows, norms)
    table, detail = [], []
    for scene, group in rows.groupby("scene", sort=True):
        norm = norms[scene]
        table.append({**verdict_row(scene, group, norm, noise, targets),
                      "seed paper's rates": claim_verdicts(rates, scene),
                      "failures and flags": flags(everything[everything["scene"] == scene])})
        for target in targets if norm else ():
            ranking = pd.DataFrame(cheapest(group, norm, target, noise)["ranking"][:5])
            if len(ranking):
                ranking["seconds"] = ranking["seconds"].map(sig3)
            detail.append({"scene": scene, "target": sig3(target), "norm": sig3(norm),
                           "ranking": ranking})
    return {"table": pd.DataFrame(table), "detail": detail, "noise": noise_text(noise)}

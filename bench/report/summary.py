"""The report's first screen: per scene, which combination reaches a stated accuracy fastest
(from the work-precision data), each estimator's effectivity range, the verdicts on the seed
paper's claimed rates, and any failure or flag."""

from __future__ import annotations

import numpy as np
import pandas as pd

from bench.matrix.rates import judged_levels
from bench.sequence.rows import KEYS, phase_time
from formulations import STATUS_FAILED, STATUS_OK

COMBINATION = ["formulation", "solver", "estimator", "strategy", "order"]


def sig3(value: float) -> str:
    """Three significant figures, never an exponent in prose: 2120, 0.000341, 4.4."""
    return np.format_float_positional(float(value), precision=3, unique=False,
                                      fractional=False, trim="-")


def _error_column(group: pd.DataFrame) -> str:
    return "energy_error" if group["energy_error"].gt(0).any() else "eta"


def _target(finals: pd.Series) -> float:
    """The stated accuracy: the median of the combinations' final errors, to two digits
    rounded up, so that about half of the combinations reach it."""
    median = float(np.median(finals))
    scale = 10.0 ** (np.floor(np.log10(median)) - 1)
    return float(np.ceil(median / scale) * scale)


def fastest(group: pd.DataFrame) -> dict:
    """The target accuracy, the combinations reaching it sorted by cumulative wall time up to
    their first level below it, and how many combinations were compared."""
    column = _error_column(group)
    ok = group[(group["status"] == STATUS_OK) & group[column].gt(0)].sort_values("level")
    if ok.empty:
        return {"column": column, "target": float("nan"), "ranking": [], "compared": 0}
    sequences = [seq.assign(cumulative=phase_time(seq).cumsum())
                 for _, seq in ok.groupby(KEYS, sort=True, dropna=False)]
    target = _target(pd.Series([seq[column].iloc[-1] for seq in sequences]))
    ranking = []
    for seq in sequences:
        below = seq[seq[column] <= target]
        if len(below):
            first = below.iloc[0]
            cell = str(first.get("cell", "tri"))
            ranking.append({"combination": "/".join(str(first[k]) for k in COMBINATION[:4])
                            + ("" if cell in ("tri", "nan") else f"/{cell}"),
                            "order": int(first["order"]), "ndofs": int(first["ndofs"]),
                            "seconds": float(first["cumulative"])})
    ranking.sort(key=lambda r: r["seconds"])
    return {"column": column, "target": target, "ranking": ranking, "compared": len(sequences)}


EFFECTIVITY_FROM_DOFS = 1000  # coarse levels are pre-asymptotic for every estimator


def effectivity_ranges(group: pd.DataFrame) -> str:
    """Per estimator, min..max of eta / error over the judged levels from
    ``EFFECTIVITY_FROM_DOFS`` DOFs (all judged levels where none is that fine)."""
    judged = judged_levels(group)
    fine = judged[judged["ndofs"] >= EFFECTIVITY_FROM_DOFS]
    judged = fine if len(fine) else judged
    parts = [f"{name} {sig3(eff.min())}..{sig3(eff.max())}"
             for name, eff in judged.groupby("estimator")["effectivity_index"]]
    return "; ".join(parts) if parts else "no truth sharp enough"


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


def first_screen(everything: pd.DataFrame, rows: pd.DataFrame, rates: pd.DataFrame) -> dict:
    """The summary table (one row per scene) and the detail behind its 'fastest' column."""
    table, detail = [], []
    for scene, group in rows.groupby("scene", sort=True):
        best = fastest(group)
        top = best["ranking"][0] if best["ranking"] else None
        measure = "error" if best["column"] == "energy_error" else "eta (no truth)"
        table.append({
            "scene": scene,
            f"fastest to {measure} <= target": (
                f"{top['combination']} P{top['order']}: {top['seconds']:.3g} s "
                f"({top['ndofs']} DOFs; target {best['target']:.2g}, reached by "
                f"{len(best['ranking'])} of {best['compared']})" if top else "none reached"),
            f"effectivity from {EFFECTIVITY_FROM_DOFS} DOFs (min..max)":
                effectivity_ranges(group),
            "seed paper's rates": claim_verdicts(rates, scene),
            "failures and flags": flags(everything[everything["scene"] == scene])})
        ranking = pd.DataFrame(best["ranking"][:5])
        if len(ranking):
            ranking["seconds"] = ranking["seconds"].map(lambda t: f"{t:.3g}")
        detail.append({"scene": scene, "target": best["target"], "measure": measure,
                       "ranking": ranking})
    return {"table": pd.DataFrame(table), "detail": detail}

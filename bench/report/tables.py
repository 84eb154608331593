"""The report's tables, as DataFrames of formatted strings (both templates show the same)."""

from __future__ import annotations

from dataclasses import fields

import numpy as np
import pandas as pd

from bench.matrix.rates import judged_levels
from bench.measure.contact import STATUS_UNRESOLVED
from bench.measure.slope import SlopeFit
from bench.report.verdict import EFFECTIVITY_FROM_DOFS
from bench.sequence.rows import KEYS, LABELS, phase_time
from bench.verify import claims
from estimators import guaranteed_estimators
from estimators.base import BoundTerms
from formulations import STATUS_OK

CLAIM_TOLERANCE = 0.05  # "about" a claimed slope: a verdict agrees if its interval meets this band
MAX_INTERVAL = 0.1  # a 95 % interval wider than this is too coarse to judge
# a slope is a verdict only from this many levels whose last has at least this many DOFs:
# fewer, coarser levels are pre-asymptotic (a 3-level fit under 600 DOFs says nothing)
MIN_FIT_LEVELS = 4
MIN_VERDICT_DOFS = 2000
TIME_SHIFT = 1.0  # s, shift of the shifted geometric mean of times
VERDICTS = ("agrees", "steeper than claimed", "shallower than claimed", "error grows",
            "too coarse to judge", "not measured")


def _fmt(value, spec=".3g") -> str:
    if value is None or (isinstance(value, float) and not np.isfinite(value)):
        return ""
    return format(value, spec) if isinstance(value, (int, float, np.floating, np.integer)) \
        else str(value)


def rate_verdict(fit: SlopeFit, claimed: float, levels: int = MIN_FIT_LEVELS,
                 ndofs: int = MIN_VERDICT_DOFS) -> str:
    """One of VERDICTS for a fitted slope and its 95 % interval against the claimed slope:
    "agrees" only where the interval meets claimed +- CLAIM_TOLERANCE, "too coarse to judge"
    from too few or too coarse levels or an interval wider than MAX_INTERVAL, "error grows"
    where the whole interval is above 0."""
    if not np.isfinite(fit.slope):
        return "not measured"
    if levels < MIN_FIT_LEVELS or ndofs < MIN_VERDICT_DOFS or not fit.width <= MAX_INTERVAL:
        return "too coarse to judge"
    if fit.low > 0:
        return "error grows"
    if fit.meets(claimed - CLAIM_TOLERANCE, claimed + CLAIM_TOLERANCE):
        return "agrees"
    return "steeper than claimed" if fit.high < claimed else "shallower than claimed"


def _fit(r: pd.Series, name: str) -> SlopeFit:
    return SlopeFit(r[name], np.nan, r.get(f"{name}_low", np.nan),
                    r.get(f"{name}_high", np.nan), int(r.get("fit_levels", 0)))


def rate_verdicts(rates: pd.DataFrame) -> pd.DataFrame:
    """Measured slopes with their 95 % intervals beside the claimed ones (``[[claim]]`` in
    expected.toml), one verdict each (``rate_verdict``) from the error's slope (eta's where
    no error was measured)."""
    rows, claimed_slopes = [], claims()
    for _, r in rates.iterrows():
        claimed, source = claimed_slopes.get((r["scene"], r["strategy"], int(r.get("order", 1))),
                                             (np.nan, "no claim"))
        fit = _fit(r, "error_rate" if np.isfinite(r["error_rate"]) else "eta_rate")
        pressure = r.get("pressure_error_rate", np.nan)
        rows.append({"scene": r["scene"], "formulation": r["formulation"],
                     "estimator": r["estimator"], "strategy": r["strategy"],
                     "order": int(r.get("order", 1)), **{c: r.get(c, "") for c in LABELS},
                     "error rate [95 % interval]": _fit(r, "error_rate").text(),
                     "eta rate [95 % interval]": _fit(r, "eta_rate").text(),
                     "pressure error rate": _fmt(pressure),
                     "claimed": _fmt(claimed), "source": source,
                     "verdict": rate_verdict(fit, claimed, int(r.get("fit_levels", 0)),
                                             int(r.get("ndofs_last", 0)))
                     if np.isfinite(claimed) else "",
                     "note": "the pressure error grows" if np.isfinite(pressure)
                     and pressure > 0 else ""})
    return without_empty_labels(pd.DataFrame(rows))


def effectivity_table(rates: pd.DataFrame) -> pd.DataFrame:
    if rates.empty:
        return pd.DataFrame()
    return without_empty_labels(pd.DataFrame({
        "scene": rates["scene"], "formulation": rates["formulation"],
        "estimator": rates["estimator"], "strategy": rates["strategy"],
        "order": rates["order"] if "order" in rates else 1,
        **{c: rates[c] for c in LABELS if c in rates},
        "last": rates["effectivity_last"].map(_fmt), "min": rates["effectivity_min"].map(_fmt),
        "max": rates["effectivity_max"].map(_fmt),
        "max/min": rates["effectivity_variation"].map(_fmt),
        # --target-error's DOFs over an oracle's (bench/matrix/rates.py); bounds only
        "DOFs for eta vs error": [_fmt(r) if e in guaranteed_estimators() else "" for e, r in
                                  zip(rates["estimator"], rates["target_dofs_ratio"],
                                      strict=True)],
        "rows with too coarse reference": rates["too_coarse_rows"]}))


def estimator_summary(rows: pd.DataFrame) -> pd.DataFrame:
    """Per estimator, over every judged level of every scene, formulation, order and strategy:
    the effectivity range and how often eta fell below the error (sharp vs safe)."""
    judged = judged_levels(rows)
    out = []
    for name, group in judged.groupby("estimator", sort=True):
        eff = group["effectivity_index"]
        late = group.loc[group["ndofs"] >= EFFECTIVITY_FROM_DOFS, "effectivity_index"]
        out.append({"estimator": name,
                    "guaranteed bound": "yes" if name in guaranteed_estimators() else "no",
                    "levels": len(eff), "min": _fmt(eff.min()), "median": _fmt(eff.median()),
                    "max": _fmt(eff.max()),
                    "range from 1e3 DOFs": f"{_fmt(late.min())} .. {_fmt(late.max())}"
                    if len(late) else "",
                    "levels with eta < error": f"{int((eff < 1).sum())} "
                                               f"({100 * float((eff < 1).mean()):.0f} %)",
                    "parts of the bound from 1e3 DOFs": bound_parts_text(group),
                    "largest part at the max from 1e3 DOFs": worst_part_text(group)})
    return pd.DataFrame(out)


def _part_shares(group: pd.DataFrame) -> pd.DataFrame:
    """Each part of a guaranteed bound's A + N (``BoundTerms``) over their sum, on the levels
    from 1e3 DOFs that report them."""
    columns = [f"eta_{f.name}" for f in fields(BoundTerms) if f"eta_{f.name}" in group]
    late = group.loc[group["ndofs"] >= EFFECTIVITY_FROM_DOFS, columns].dropna()
    late = late[late.sum(axis=1) > 0]
    return late.div(late.sum(axis=1), axis=0)


def _part_name(column: str) -> str:
    return column.removeprefix("eta_").replace("_", " ")


def bound_parts_text(group: pd.DataFrame) -> str:
    """The median share of each part of a guaranteed bound's A + N (``BoundTerms``) over the
    levels from 1e3 DOFs, largest first ('' for an estimator without parts)."""
    shares = _part_shares(group)
    if shares.empty:
        return ""
    median = shares.median().sort_values(ascending=False)
    return ", ".join(f"{_part_name(name)} {100 * share:.0f} %"
                     for name, share in median.items() if share >= 0.005)


def worst_part_text(group: pd.DataFrame) -> str:
    """The part that dominates A + N on the level of largest effectivity from 1e3 DOFs, with
    its share and the level ('' for an estimator without parts): where the bound is
    loosest, what makes it so."""
    shares = _part_shares(group)
    if shares.empty:
        return ""
    worst = group.loc[shares.index, "effectivity_index"].idxmax()
    part, level = shares.loc[worst].idxmax(), group.loc[worst]
    return (f"{_part_name(part)} {100 * shares.loc[worst, part]:.0f} % ({level['scene']}, "
            f"{level['formulation']}, {level['strategy']} P{int(level['order'])}, "
            f"{int(level['ndofs'])} DOFs, effectivity {_fmt(level['effectivity_index'])})")


def _total_time(group: pd.DataFrame) -> float:
    return float(phase_time(group).sum())


def without_empty_labels(table: pd.DataFrame) -> pd.DataFrame:
    """The table without sweep label columns that are empty in every row."""
    empty = [c for c in LABELS if c in table and not table[c].astype(str).str.len().any()]
    return table.drop(columns=empty)


def accuracy_table(rows: pd.DataFrame) -> pd.DataFrame:
    out = []
    for key, group in rows.groupby(KEYS, sort=True, dropna=False):
        last = group.sort_values("level").iloc[-1]
        out.append({**dict(zip(KEYS, key, strict=True)), "ndofs": int(last["ndofs"]),
                    "energy": _fmt(last["energy"], ".6g"),
                    "contact force": _fmt(last["contact_force"], ".6g"),
                    "error": _fmt(last["energy_error"]), "eta": _fmt(last["eta"]),
                    "eta_0": _fmt(last["eta_0"]), "eta_geometric": _fmt(last["eta_geometric"]),
                    "eta_compl.": _fmt(last["eta_complementarity"]),
                    "effectivity": _fmt(last["effectivity_index"]),
                    "zone": f"[{_fmt(last['contact_zone_start'], '.4g')}, "
                            f"{_fmt(last['contact_zone_end'], '.4g')}]",
                    "iterations": int(last["iterations"]),
                    "pressure oscillation": _fmt(last.get("pressure_oscillation")),
                    "inf-sup": _fmt(last.get("inf_sup")),
                    "total time [s]": _fmt(_total_time(group), ".3g"), "status": last["status"]})
    return without_empty_labels(pd.DataFrame(out))


def timing_table(rows: pd.DataFrame) -> pd.DataFrame:
    """Shifted geometric mean over scenes of each sequence's total wall time, normalised by
    the best combination: exp(mean(log(t + s))) - s with shift s = TIME_SHIFT."""
    keys = ["formulation", "solver", "estimator", "strategy"]
    totals = rows.groupby(["scene", *keys]).apply(_total_time, include_groups=False)
    if totals.empty:
        return pd.DataFrame()
    totals = totals.rename("t").reset_index()
    sgm = totals.groupby(keys)["t"].apply(
        lambda t: float(np.exp(np.mean(np.log(t + TIME_SHIFT))) - TIME_SHIFT))
    best = sgm.min()
    out = sgm.rename("shifted geometric mean [s]").reset_index()
    out["relative to best"] = (sgm.values / best) if best > 0 else np.nan
    out["scenes"] = totals.groupby(keys)["scene"].nunique().values
    out["shifted geometric mean [s]"] = out["shifted geometric mean [s]"].map(_fmt)
    out["relative to best"] = out["relative to best"].map(lambda v: _fmt(v, ".2f"))
    return out.sort_values("relative to best")


def agreement_table(rows: pd.DataFrame) -> pd.DataFrame:
    checked = rows[rows["crosscheck_status"].astype(object).fillna("").astype(str) != ""]
    if checked.empty:
        return pd.DataFrame()
    keys = ["scene", "formulation", "solver"]
    out = checked.groupby(keys).agg(
        levels=("level", "count"), max_ndofs=("ndofs", "max"),
        energy_norm=("crosscheck_energy_difference", "max"),
        pressure=("crosscheck_pressure_difference", "max"),
        reference_ok=("crosscheck_status", lambda s: int((s == STATUS_OK).sum()))).reset_index()
    out["energy_norm"] = out["energy_norm"].map(lambda v: _fmt(v, ".1e"))
    out["pressure"] = out["pressure"].map(lambda v: _fmt(v, ".1e"))
    return out.rename(columns={"energy_norm": "max rel. energy-norm difference",
                               "pressure": "max rel. pressure difference",
                               "reference_ok": "reference ok"})


UNRESOLVED_REASON = ("the discrete constraint did not see the contact: the penetration undoes "
                     "more than 10 % of the obstacle's approach, or nothing is active where it "
                     "is pushed in (docs/theory.md 19.1); usually the coarsest levels")


def failure_table(everything: pd.DataFrame) -> pd.DataFrame:
    """Every row not ok, identical ones (same status and reason) in one line with their count
    and the first combinations."""
    bad = everything[everything["status"].fillna("missing") != STATUS_OK]
    if bad.empty:
        return pd.DataFrame()
    bad = bad.assign(reason=bad["reason"].fillna("").astype(str),
                     combination=bad[KEYS[:5]].astype(str).agg("/".join, axis=1))
    # each unresolved row states its own figure: one line for all of them, with the worst
    unresolved = bad["status"] == STATUS_UNRESOLVED
    bad.loc[unresolved, "reason"] = UNRESOLVED_REASON
    out = []
    for (status, reason), group in bad.groupby(["status", "reason"], sort=True):
        names = list(dict.fromkeys(group["combination"]))
        shown = ", ".join(names[:3]) + (f" and {len(names) - 3} more" if len(names) > 3 else "")
        if status == STATUS_UNRESOLVED and "penetration_share" in group:
            reason += f"; the worst undoes {group['penetration_share'].max():.0%}"
        out.append({"status": status, "rows": len(group), "reason": reason,
                    "combinations": shown})
    return pd.DataFrame(out).sort_values("rows", ascending=False)


def rate_counts(rates: pd.DataFrame) -> str:
    """'Verdicts: 20 agree, 3 steeper than claimed, ...' over the slopes with a claim."""
    if rates.empty or "verdict" not in rates:
        return ""
    counts = rates.loc[rates["verdict"] != "", "verdict"].value_counts()
    return ("Verdicts: " + ", ".join(f"{n} {v}" for v, n in counts.items()) + ".") \
        if len(counts) else ""

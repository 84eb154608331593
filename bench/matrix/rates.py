"""The rates table: convergence slopes and effectivity per combination.

The slope of log(y) against log(ndofs) is fitted by least squares (``bench.measure.slope``,
with its 95 % interval: columns ``*_rate_low`` and ``*_rate_high``) over the last
``RATE_LEVELS`` ok levels that have y > 0 (earlier levels are pre-asymptotic: on the paper
scene nothing touches on the first two). In 2D, O(h^1/2) is slope -1/4 and O(h) is slope -1/2.
Effectivity statistics use the same levels and skip rows whose reference is too coarse;
``effectivity_all_min`` is the minimum over every level (for a guaranteed bound);
``effectivity_total_all_min`` and ``effectivity_total_max`` those of eta_total / error, the
second from TOTAL_FROM_DOFS unknowns.
``target_dofs_ratio`` prices ``--target-error`` against an oracle that knew the true error: for
TOL = eta on each of those levels, the level's DOFs over the DOFs at which the error of the same
sequence first falls to TOL (log-log interpolation between its judged levels); the largest
(docs/guaranteed.md). Above 1 the bound asks for more DOFs than the error needs.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from bench.matrix.files import atomic_text, atomic_write
from bench.measure.slope import SlopeFit, fit_slope
from bench.sequence.rows import KEYS, with_labels
from formulations import STATUS_OK

RATE_LEVELS = 4
TOTAL_FROM_DOFS = 1000  # eta_total's effectivity from here: coarser levels are pre-asymptotic


def slope_fit(group: pd.DataFrame, column: str, levels: int = RATE_LEVELS) -> SlopeFit:
    """The slope of ``column`` over the DOFs on the last ``levels`` ok levels with a value > 0,
    with its 95 % interval (``bench.measure.slope``)."""
    ok = group[(group["status"] == STATUS_OK) & (group[column] > 0)].sort_values("ndofs")
    ok = ok.tail(levels)
    return fit_slope(ok["ndofs"], ok[column])


def slope(group: pd.DataFrame, column: str, levels: int = RATE_LEVELS) -> float:
    return slope_fit(group, column, levels).slope


def slope_columns(group: pd.DataFrame, column: str, name: str, levels: int) -> dict:
    """``name`` (the slope) and ``name_low``, ``name_high`` (its 95 % interval)."""
    fit = slope_fit(group, column, levels)
    return {name: fit.slope, f"{name}_low": fit.low, f"{name}_high": fit.high}


def judged_levels(rows: pd.DataFrame) -> pd.DataFrame:
    """The solved levels with an effectivity index whose truth is sharp enough to judge it."""
    if "effectivity_index" not in rows:
        return rows.iloc[:0]
    ok = rows[(rows["status"] == STATUS_OK) & (rows["effectivity_index"] > 0)]
    return ok[~ok["reference_too_coarse"].fillna(False).astype(bool)]


def target_dofs_ratio(judged: pd.DataFrame, window: pd.DataFrame) -> float:
    """The largest N_l / N_oracle(eta_l) over the levels l of ``window`` (module docstring);
    NaN where the error of ``judged`` never falls to eta_l."""
    judged = judged.sort_values("ndofs")
    n, error = np.log(judged["ndofs"].to_numpy()), np.log(judged["energy_error"].to_numpy())
    ratios = []
    for _, level in window.iterrows():
        below = np.flatnonzero(error <= np.log(level["eta"]))
        if below.size == 0:
            return float("nan")
        first = below[0]
        if first == 0:
            crossing = n[0]
        else:  # between the last level above TOL and the first one at or below it
            share = (error[first - 1] - np.log(level["eta"])) / (error[first - 1] - error[first])
            crossing = n[first - 1] + share * (n[first] - n[first - 1])
        ratios.append(np.exp(np.log(level["ndofs"]) - crossing))
    return float(max(ratios)) if ratios else float("nan")


def total_effectivity(judged: pd.DataFrame) -> dict:
    """eta_total / error (docs/theory.md, 18) over every judged level (its minimum: where the
    bound of the returned iterate must hold) and over those from TOTAL_FROM_DOFS unknowns (its
    maximum); NaN where the levels have no eta_total."""
    values = judged["effectivity_total"] if "effectivity_total" in judged else judged["ndofs"] * \
        np.nan
    values = values.astype(float)
    late = values[judged["ndofs"] >= TOTAL_FROM_DOFS].dropna()
    return {"effectivity_total_all_min": float(values.min()) if values.notna().any()
            else float("nan"),
            "effectivity_total_max": float(late.max()) if len(late) else float("nan")}


def rates_table(table: pd.DataFrame, levels: int = RATE_LEVELS) -> pd.DataFrame:
    rows = []
    table = with_labels(table[table["level"] >= 0])
    for key, group in table.groupby(KEYS, sort=True, dropna=False):
        group = group.sort_values("level")
        ok = group[group["status"] == STATUS_OK]
        tail = ok.tail(levels)
        usable = judged_levels(tail)
        effectivity = usable["effectivity_index"] if len(usable) else pd.Series(dtype=float)
        judged = judged_levels(ok)
        rows.append({
            **dict(zip(KEYS, key, strict=True)),
            "dim": int(group["dim"].iloc[0]) if "dim" in group else 2,
            "levels": len(group), "fit_levels": len(tail),
            "ndofs_last": int(group["ndofs"].iloc[-1]),
            **slope_columns(group, "energy_error", "error_rate", levels),
            **slope_columns(group, "eta", "eta_rate", levels),
            "pressure_error_rate": slope(group, "pressure_error", levels),
            "effectivity_last": float(tail["effectivity_index"].iloc[-1]) if len(tail) else
            float("nan"),
            "effectivity_min": float(effectivity.min()) if len(effectivity) else float("nan"),
            "effectivity_max": float(effectivity.max()) if len(effectivity) else float("nan"),
            "effectivity_variation": float(effectivity.max() / effectivity.min())
            if len(effectivity) else float("nan"),
            # over every judged level, not only the last ones: where a bound must hold
            "effectivity_all_min": float(judged["effectivity_index"].min()) if len(judged)
            else float("nan"),
            "target_dofs_ratio": target_dofs_ratio(judged, usable),
            **total_effectivity(judged),
            "too_coarse_rows": int(tail["reference_too_coarse"].astype(bool).sum()),
            "truth": str(group["truth"].iloc[-1]),
        })
    return pd.DataFrame(rows)


def write_rates(table: pd.DataFrame, out: str | Path) -> Path:
    """rates.csv and rates.md next to the results."""
    out = Path(out)
    rates = rates_table(table)
    atomic_write(rates, out / "rates.csv", "csv")
    atomic_text(
        f"Slopes over the last {RATE_LEVELS} levels (-1/4 = O(h^1/2), -1/2 = O(h)).\n\n"
        + rates.to_markdown(index=False, floatfmt=".3g") + "\n", out / "rates.md")
    return out / "rates.md"

"""The error components of the returned iterates and what the adaptive stopping rule saves
(docs/theory.md, section 18): one figure and one table from the result rows."""

from __future__ import annotations

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from bench.sequence.rows import KEYS, with_labels

COMPONENTS = ["eta_total", "eta_disc", "eta_lin", "eta_alg"]
STOPPING_CAPTION = ("The error components of every level's returned iterate against the "
                    "Krylov iterations spent so far, for the adaptively stopped sequence with "
                    "the most unknowns (solid) and the same combination with the fixed "
                    "tolerances (dashed, where run): eta_total bounds the error of the iterate "
                    "(with a guaranteed estimator), eta_alg and eta_lin are what the iteration "
                    "left (docs/theory.md, 18).")
SAME = [k for k in KEYS if k != "stopping"]  # a combination, whatever its stopping rule


def _solved(rows: pd.DataFrame) -> pd.DataFrame:
    if "eta_total" not in rows or rows.empty:
        return rows.iloc[:0]
    rows = with_labels(rows)
    return rows[(rows["status"] == "ok") & np.isfinite(rows["eta_total"].astype(float))]


def adaptive_sequence(rows: pd.DataFrame) -> tuple[pd.DataFrame, pd.DataFrame] | None:
    """The adaptively stopped sequence with the most unknowns, and its combination's fixed
    one (empty if not run); None without adaptive rows."""
    solved = _solved(rows)
    adaptive = solved[solved["stopping"] == "adaptive"]
    if adaptive.empty:
        return None
    last = adaptive.loc[adaptive["ndofs"].idxmax()]
    same = (solved[SAME] == last[SAME]).all(axis=1)
    return tuple(solved[same & (solved["stopping"] == rule)].sort_values("level")
                 for rule in ("adaptive", "fixed"))


def components_figure(rows: pd.DataFrame) -> Figure | None:
    """eta_total, eta_disc, eta_lin, eta_alg and the error against cumulative Krylov
    iterations (``adaptive_sequence``)."""
    pair = adaptive_sequence(rows)
    if pair is None:
        return None
    fig = Figure(figsize=(8, 4))
    ax = fig.subplots()
    for frame, style in zip(pair, ("-", "--"), strict=True):
        if frame.empty:
            continue
        work = frame["krylov_iterations"].cumsum().clip(lower=1)
        names = COMPONENTS if style == "-" else ["eta_total"]
        for name in [*names, "energy_error"]:
            values = frame[name].astype(float).where(lambda v: v > 0)
            label = f"{name} ({frame['stopping'].iloc[0]})"
            ax.loglog(work, values, style, marker=".", label=label)
    errors = pair[0]["energy_error"].astype(float)
    if (errors > 0).any():  # round-off components below a thousandth of the error: not shown
        ax.set_ylim(bottom=float(errors[errors > 0].min()) * 1e-3)
    ax.set_xlabel("Krylov iterations, cumulative over the levels")
    ax.set_ylabel("energy norm")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    return fig


def work_saved(rows: pd.DataFrame) -> pd.DataFrame:
    """Per combination run with both rules (its sequences to the same budget): Krylov
    iterations, Newton steps and solve time summed over the levels, the last level's
    eta_total and error, and the ratios fixed / adaptive."""
    solved = _solved(rows)
    out = []
    for key, group in solved.groupby(SAME, sort=True, dropna=False):
        rules = {rule: g for rule, g in group.groupby("stopping")}
        if {"fixed", "adaptive"} - set(rules):
            continue
        totals = {rule: dict(krylov=int(g["krylov_iterations"].sum()),
                             steps=int(g["newton_steps"].sum()),
                             solve=float(g["t_solve"].sum()),
                             ndofs=int(g["ndofs"].iloc[-1]),
                             total=float(g.sort_values("level")["eta_total"].iloc[-1]),
                             error=float(g.sort_values("level")["energy_error"].iloc[-1]))
                  for rule, g in rules.items()}
        fixed, adaptive = totals["fixed"], totals["adaptive"]
        out.append({"combination": "/".join(str(k) for k in key if str(k)),
                    "last DOFs (fixed / adaptive)": f"{fixed['ndofs']} / {adaptive['ndofs']}",
                    "Krylov (fixed / adaptive)": f"{fixed['krylov']} / {adaptive['krylov']}",
                    "Krylov saved": _ratio(fixed["krylov"], adaptive["krylov"]),
                    "steps (fixed / adaptive)": f"{fixed['steps']} / {adaptive['steps']}",
                    "solve s (fixed / adaptive)": f"{fixed['solve']:.3g} / "
                                                  f"{adaptive['solve']:.3g}",
                    "solve time saved": _ratio(fixed["solve"], adaptive["solve"]),
                    "last error (fixed / adaptive)": f"{fixed['error']:.3g} / "
                                                     f"{adaptive['error']:.3g}",
                    "last eta_total (fixed / adaptive)": f"{fixed['total']:.3g} / "
                                                         f"{adaptive['total']:.3g}"})
    return pd.DataFrame(out)


def _ratio(fixed: float, adaptive: float) -> float:
    return float(fixed / adaptive) if adaptive > 0 else float("nan")

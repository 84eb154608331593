"""The report's polynomial-order section (docs/theory.md, section 9): rates and effectivity per
order, and which order reaches a relative energy-norm error of 1e-3 first, at what cost."""

from __future__ import annotations

import pandas as pd
from matplotlib.figure import Figure

from bench.report.figures import marker
from bench.report.ranking import rank
from bench.sequence.rows import phase_time
from bench.truth.norms import exact_energy_norm
from formulations import STATUS_OK

TARGET = 1e-3  # relative energy-norm error


ORDER_COLOURS = ["tab:blue", "tab:orange", "tab:green", "tab:red"]


def order_work_precision(table: pd.DataFrame, norm: float | None = None):
    """Energy error (relative to ``norm`` when given) against the cumulative wall time of its
    sequence, one line per sequence, coloured by polynomial order; uniform dashed, adaptive
    solid. None unless the table has several orders and errors."""
    if "order" not in table or table["order"].nunique() < 2 or \
            not table["energy_error"].gt(0).any():
        return None
    fig = Figure(figsize=(8, 4.5))
    ax = fig.subplots()
    orders, labelled = sorted(table["order"].unique()), set()
    for key, group in table.groupby(["formulation", "estimator", "strategy", "order"]):
        group = group[group["status"] == STATUS_OK].sort_values("level")
        ax.loglog(phase_time(group).cumsum(), group["energy_error"] / (norm or 1.0),
                  linewidth=0.8, marker=marker(key[2]), markersize=2,
                  color=ORDER_COLOURS[orders.index(key[3]) % len(ORDER_COLOURS)],
                  linestyle="-" if key[2] == "adaptive" else "--",
                  label=None if key[3] in labelled else f"P{key[3]}")
        labelled.add(key[3])
    if norm:
        ax.axhline(TARGET, color="k", linewidth=0.6)
    ax.set_xlabel("cumulative wall time of the sequence [s]")
    ax.set_ylabel("||u - u_h|| / ||u||" if norm else "||u - u_h||")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    return fig


def first_to_target(rows: pd.DataFrame, norm: float) -> pd.DataFrame:
    """Per order and strategy, the sequence whose relative error first falls to TARGET in the
    least cumulative wall time (``bench.report.ranking.rank``), with its DOFs; 'not
    reached' within the budget otherwise."""
    out = []
    for (order, strategy), group in rows.groupby(["order", "strategy"], sort=True):
        ranking = rank(group, norm, TARGET, None).ranked
        best = ranking[0] if ranking else None
        out.append({"order": int(order), "strategy": strategy,
                    "first to 1e-3": best.combination if best else "not reached",
                    "ndofs": best.ndofs if best else "",
                    "wall time [s]": f"{best.seconds:.2f}" if best else "",
                    "smallest relative error": f"{(group['energy_error'] / norm).min():.2e}"})
    return pd.DataFrame(out)


def order_section(rows: pd.DataFrame, figs) -> list[dict]:
    """One entry per exact scene with several orders: its work-precision figure and table."""
    if "order" not in rows or rows["order"].nunique() < 2:
        return []
    sections = []
    for scene_name, group in rows.groupby("scene", sort=True):
        norm = exact_energy_norm(scene_name)
        if norm is None or group["order"].nunique() < 2:
            continue
        item = figs.add(order_work_precision(group, norm),
                        f"{scene_name}-orders", "Relative energy error against the cumulative "
                        "wall time of each sequence, coloured by order (adaptive solid, uniform "
                        "dashed); the line marks 1e-3.")
        sections.append({"scene": scene_name, "norm": norm, "figure": item,
                         "table": first_to_target(group, norm)})
    return sections

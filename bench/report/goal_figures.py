"""The report's quantities of interest (docs/report.md, "Quantities of interest"): per scene
and quantity, the relative error of the quantity against DOFs for energy-driven (``adaptive``)
and goal-driven (``goal``) refinement, and the effectivity of the goal estimate beside it."""

from __future__ import annotations

import pandas as pd
from matplotlib.figure import Figure

from bench.matrix.goals import JUDGED_FROM, TARGET, goal_table
from bench.measure.contact import SOLVED_STATUSES
from bench.report.figures import colour, marker
from bench.sequence.rows import with_labels

CAPTION = ("Quantity of interest: relative error |J(u) - J(u_h)| / |J(u)| (left) and the "
           "effectivity of the dual-weighted estimate (right) against DOFs; solid: goal-driven "
           "(strategy goal), dashed: energy-driven (adaptive); the dotted lines mark the "
           f"target {TARGET:g} and the band 0.8-1.25 judged from {JUDGED_FROM} DOFs")
TABLE_COLUMNS = ["scene", "scene_parameters", "goal", "formulation", "order", "strategy", "ndofs",
                 "qoi_relative_error", "dofs_to_target", "energy_dofs_to_target", "dofs_ratio",
                 "qoi_effectivity_min", "qoi_effectivity_max", "qoi_wrong_sign"]


def goal_figure(group: pd.DataFrame, title: str):
    """Error and effectivity against DOFs of one scene's sequences for one quantity."""
    fig = Figure(figsize=(11, 4.2))
    error_axes, effectivity_axes = fig.subplots(1, 2)
    for (formulation, order, strategy, estimator), seq in group.groupby(
            ["formulation", "order", "strategy", "estimator"], sort=True):
        seq = seq.sort_values("ndofs")
        style = dict(color=colour(formulation), marker=marker(strategy), markersize=3,
                     linestyle="-" if strategy == "goal" else "--", linewidth=1,
                     label=f"{formulation} P{order} {strategy} ({estimator})")
        error_axes.loglog(seq["ndofs"], seq["qoi_relative_error"], **style)
        effectivity_axes.semilogx(seq["ndofs"], seq["qoi_effectivity"], **style)
    error_axes.axhline(TARGET, color="0.5", linestyle=":", linewidth=0.8)
    for level in (0.8, 1.25):
        effectivity_axes.axhline(level, color="0.5", linestyle=":", linewidth=0.8)
    effectivity_axes.set_ylim(0, 2)
    error_axes.set(xlabel="DOFs", ylabel="relative error of the quantity", title=title)
    effectivity_axes.set(xlabel="DOFs", ylabel="estimate / true error")
    error_axes.legend(fontsize=6)
    for axes in (error_axes, effectivity_axes):
        axes.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    return fig


def goal_section(rows: pd.DataFrame, figs) -> dict:
    """The section's figures (one per scene and quantity with a true error) and its table."""
    rows = with_labels(rows)
    if "qoi_relative_error" not in rows or not (rows["goal"] != "").any():
        return {"figures": [], "table": pd.DataFrame()}
    solved = rows[(rows["goal"] != "") & rows["status"].isin(SOLVED_STATUSES)
                  & rows["qoi_relative_error"].notna()]
    figures = [figs.add(goal_figure(group, f"{scene}: {goal}"), f"goal-{scene}-{goal}",
                        f"{scene}, {goal}. {CAPTION}")
               for (scene, goal), group in solved.groupby(["scene", "goal"], sort=True)]
    table = goal_table(rows)
    return {"figures": [f for f in figures if f is not None],
            "table": table.reindex(columns=TABLE_COLUMNS) if len(table) else table}

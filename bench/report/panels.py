"""Small multiples: one panel per formulation, colour = estimator, marker = strategy, line style
= quantity (the true error solid, eta dashed), so that a panel has at most about 8 legend
entries however many combinations a run has; one legend outside the panels, slope triangles
where the caption names them, only decades labelled on log axes."""

from __future__ import annotations

import numpy as np
import pandas as pd
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.ticker import LogFormatterSciNotation, LogLocator, NullFormatter

from bench.report.figures import _slope_triangle, marker
from bench.sequence.rows import phase_time
from estimators import estimator_names
from formulations import STATUS_OK, formulation_names

PANEL = 3.4  # inches per panel
ESTIMATOR_COLOURS = [f"C{k}" for k in range(10)]


def estimator_colour(estimator: str) -> str:
    names = estimator_names()
    index = names.index(estimator) if estimator in names else len(names) + len(estimator)
    return ESTIMATOR_COLOURS[index % len(ESTIMATOR_COLOURS)]


def decades(ax, x: bool = True, y: bool = True) -> None:
    """Label the powers of ten of a log axis (no minor tick labels); an axis spanning less
    than two decades also labels 2 and 5 times them, so that it has more than one label."""
    for on, axis, limits in ((x, ax.xaxis, ax.get_xlim()), (y, ax.yaxis, ax.get_ylim())):
        if on:
            low, high = sorted(limits)
            narrow = low > 0 and high / low < 100
            axis.set_major_locator(LogLocator(base=10.0, numticks=12,
                                              subs=(1.0, 2.0, 5.0) if narrow else (1.0,)))
            axis.set_major_formatter(LogFormatterSciNotation(labelOnlyBase=False))
            axis.set_minor_formatter(NullFormatter())


def panel_keys(table: pd.DataFrame) -> list[str]:
    """What separates the panels: the formulation, and the order and the cells where the
    table has several (a line never mixes two of them)."""
    return ["formulation", *[c for c in ("order", "cell") if c in table
                             and table[c].nunique() > 1]]


def panel_grid(table: pd.DataFrame, height: float = PANEL):
    """A figure with one panel per formulation (and order, cells) of ``table``, in registry
    order, and the list of (title, rows, axes)."""
    known = formulation_names()
    keys = panel_keys(table)
    groups = sorted(table.groupby(keys, sort=False),
                    key=lambda item: (known.index(item[0][0]) if item[0][0] in known
                                      else len(known), item[0]))
    cols = min(len(groups), 4)
    rows = int(np.ceil(len(groups) / cols))
    fig = Figure(figsize=(PANEL * cols + 2.2, height * rows))
    axes = fig.subplots(rows, cols, squeeze=False, sharex=True, sharey=True).ravel()
    for ax in axes[len(groups):]:
        ax.set_axis_off()
    titles = [" ".join(f"P{v}" if k == "order" else str(v) for k, v in zip(keys, key,
                                                                            strict=True))
              for key, _ in groups]
    return fig, [(title, rows_, ax) for title, (_, rows_), ax in zip(titles, groups, axes,
                                                                      strict=False)]


def _ok(group: pd.DataFrame, y: str) -> pd.DataFrame:
    return group[(group["status"] == STATUS_OK) & (group[y] > 0)].sort_values("ndofs")


def legend(fig, estimators, strategies, quantities=()) -> None:
    """One legend right of the panels: estimators (colours), strategies (markers) and the
    quantities (line styles)."""
    handles = [Line2D([], [], color=estimator_colour(e), label=e) for e in estimators]
    handles += [Line2D([], [], color="0.3", marker=marker(s), linestyle="", label=s)
                for s in strategies]
    handles += [Line2D([], [], color="0.3", linestyle=style, label=label)
                for label, style in quantities]
    fig.legend(handles=handles, loc="center right", fontsize=8, frameon=False)
    fig.tight_layout(rect=(0, 0, 1 - 2.0 / fig.get_figwidth(), 1))


def convergence(table: pd.DataFrame):
    """Error (solid) and eta (dashed) against ndofs per formulation, with O(h^1/2) and O(h)
    slope triangles (the paper's Figure 2)."""
    if table.empty:
        return None
    fig, panels = panel_grid(table)
    has_error = table["energy_error"].gt(0).any()
    for name, mine, ax in panels:
        for (estimator, strategy), group in mine.groupby(["estimator", "strategy"]):
            look = dict(color=estimator_colour(estimator), marker=marker(strategy),
                        markersize=3, linewidth=1)
            eta = _ok(group, "eta")
            ax.loglog(eta["ndofs"], eta["eta"], linestyle="--", **look)
            error = _ok(group, "energy_error")
            ax.loglog(error["ndofs"], error["energy_error"], linestyle="-", **look)
        ax.set_title(name, fontsize=10)
        ax.grid(True, which="major", alpha=0.3)
        ax.set_xlabel("ndofs")
        decades(ax)
        values = [line.get_ydata() for line in ax.get_lines() if len(line.get_ydata())]
        if values:
            x = np.concatenate([line.get_xdata() for line in ax.get_lines()])
            y = np.concatenate(values)
            _slope_triangle(ax, x.min() * 3, y.max() / 2, -0.25, "-1/4: O(h^1/2)")
            _slope_triangle(ax, x.min() * 3, y.min() * 4, -0.5, "-1/2: O(h)")
    panels[0][2].set_ylabel("energy norm")
    quantities = [("error", "-"), ("eta", "--")] if has_error else [("eta", "--")]
    legend(fig, sorted(table["estimator"].unique()), sorted(table["strategy"].unique()),
           quantities)
    return fig


def effectivity(table: pd.DataFrame):
    """eta / ||u - u_h|| per level, per formulation; crosses: rows whose reference is too
    coarse."""
    if not table["effectivity_index"].gt(0).any():
        return None
    fig, panels = panel_grid(table, height=3.0)
    for name, mine, ax in panels:
        for (estimator, strategy), group in mine.groupby(["estimator", "strategy"]):
            ok = _ok(group, "effectivity_index")
            ax.semilogx(ok["ndofs"], ok["effectivity_index"], color=estimator_colour(estimator),
                        marker=marker(strategy), markersize=3, linewidth=1)
            coarse = ok[ok["reference_too_coarse"].fillna(False).astype(bool)]
            ax.semilogx(coarse["ndofs"], coarse["effectivity_index"], "x", color="k",
                        markersize=5)
        ax.axhline(1.0, color="k", linewidth=0.6)
        ax.set_yscale("log")  # coarse levels can be off by 100x and would flatten the rest
        ax.set_title(name, fontsize=10)
        ax.set_xlabel("ndofs")
        ax.grid(True, which="major", alpha=0.3)
        decades(ax)
    panels[0][2].set_ylabel("eta / ||u - u_h||")
    legend(fig, sorted(table["estimator"].unique()), sorted(table["strategy"].unique()))
    return fig


def formulation_colour(formulation: str) -> str:
    names = formulation_names()
    index = names.index(formulation) if formulation in names else len(names) + len(formulation)
    return ESTIMATOR_COLOURS[index % len(ESTIMATOR_COLOURS)]


def work_precision(table: pd.DataFrame):
    """The error (eta without a truth) against the cumulative wall time of the sequence: one
    panel per polynomial order, colour = formulation, marker = strategy (one line per
    estimator); with one order, one panel per formulation, colour = estimator."""
    y = "energy_error" if table["energy_error"].gt(0).any() else "eta"
    orders = sorted(table["order"].unique()) if "order" in table else [1]
    if len(orders) < 2:
        return _work_precision_by_formulation(table, y)
    fig = Figure(figsize=(PANEL * len(orders) + 2.2, 3.2))
    axes = fig.subplots(1, len(orders), squeeze=False, sharey=True)[0]
    for ax, order in zip(axes, orders, strict=True):
        mine = table[table["order"] == order]
        for (formulation, _, strategy), group in mine.groupby(["formulation", "estimator",
                                                                "strategy"]):
            ok = group[group["status"] == STATUS_OK].sort_values("level")
            ax.loglog(phase_time(ok).cumsum(), ok[y], color=formulation_colour(formulation),
                      marker=marker(strategy), markersize=2.5, linewidth=0.8)
        ax.set_title(f"P{order}", fontsize=10)
        ax.set_xlabel("cumulative wall time [s]")
        ax.grid(True, which="major", alpha=0.3)
        decades(ax)
    axes[0].set_ylabel("||u - u_h||" if y == "energy_error" else "eta (no truth)")
    handles = [Line2D([], [], color=formulation_colour(f), label=f)
               for f in sorted(table["formulation"].unique())]
    handles += [Line2D([], [], color="0.3", marker=marker(s), linestyle="", label=s)
                for s in sorted(table["strategy"].unique())]
    fig.legend(handles=handles, loc="center right", fontsize=8, frameon=False)
    fig.tight_layout(rect=(0, 0, 1 - 2.0 / fig.get_figwidth(), 1))
    return fig


def _work_precision_by_formulation(table: pd.DataFrame, y: str):
    fig, panels = panel_grid(table, height=3.0)
    for name, mine, ax in panels:
        for (estimator, strategy), group in mine.groupby(["estimator", "strategy"]):
            ok = group[group["status"] == STATUS_OK].sort_values("level")
            ax.loglog(phase_time(ok).cumsum(), ok[y], color=estimator_colour(estimator),
                      marker=marker(strategy), markersize=3, linewidth=1)
        ax.set_title(name, fontsize=10)
        ax.set_xlabel("cumulative wall time [s]")
        ax.grid(True, which="major", alpha=0.3)
        decades(ax)
    panels[0][2].set_ylabel("||u - u_h||" if y == "energy_error" else "eta (no truth)")
    legend(fig, sorted(table["estimator"].unique()), sorted(table["strategy"].unique()))
    return fig

"""The HTML report's interactive figures (plotly): convergence, effectivity and
work-precision per scene. Hovering a point shows its row (combination, level, DOFs, value);
clicking a legend entry toggles a combination. The page inlines plotly's JavaScript once
(``PLOTLY_JS``), so it stays one self-contained file that works offline; the Markdown report
keeps the matplotlib PNGs of the same data."""

from __future__ import annotations

import functools

import pandas as pd
from matplotlib.colors import to_hex

from bench.matrix.artifacts import file_stem
from bench.report.figures import _order_key, colour
from bench.sequence.rows import phase_time
from formulations import STATUS_OK

DASHES = ("solid", "dash", "dot", "dashdot", "longdash", "longdashdot")
SYMBOLS = {"uniform": "square", "adaptive": "circle"}


@functools.cache
def plotly_js() -> str:
    from plotly.offline import get_plotlyjs

    return get_plotlyjs()


def _combinations(table: pd.DataFrame):
    keys = ["formulation", "solver", "estimator", "strategy", *_order_key(table)]
    estimators = sorted(table["estimator"].unique())
    for key, group in table.groupby(keys, sort=True):
        group = group[group["status"] == STATUS_OK].sort_values("level")
        if len(group):
            style = dict(color=to_hex(colour(key[0])),
                         dash=DASHES[estimators.index(key[2]) % len(DASHES)])
            yield "/".join(map(str, key)), group, style, SYMBOLS.get(key[3], "diamond")


def _figure(table: pd.DataFrame, x: str, ys: list[tuple[str, str]], x_title: str,
            y_title: str, x_values=None):
    import plotly.graph_objects as go

    fig = go.Figure()
    for name, group, line, symbol in _combinations(table):
        xs = group[x] if x_values is None else x_values(group)
        for column, suffix in ys:
            values = group[column]
            if not values.gt(0).any():
                continue
            fig.add_trace(go.Scatter(
                x=xs, y=values, mode="lines+markers", name=f"{name}{suffix}",
                legendgroup=name, line=dict(line, width=1.5 if suffix == "" else 1),
                marker=dict(symbol=symbol, size=6), opacity=1.0 if suffix == "" else 0.6,
                customdata=group[["level", "ndofs"]].to_numpy(),
                hovertemplate=(f"<b>{name}{suffix}</b><br>level %{{customdata[0]}}, "
                               f"%{{customdata[1]}} DOFs<br>{x_title}: %{{x:.4g}}<br>"
                               f"{column}: %{{y:.4g}}<extra></extra>")))
    if not fig.data:
        return None
    fig.update_xaxes(type="log", title=x_title)
    fig.update_yaxes(type="log", title=y_title)
    fig.update_layout(height=460, margin=dict(l=60, r=10, t=30, b=50), template="plotly_white",
                      legend=dict(font=dict(size=10)), hovermode="closest")
    return fig


def interactive_figures(table: pd.DataFrame, scene: str) -> dict[str, str]:
    """HTML fragments (no script tag for plotly itself) by figure suffix: ``convergence``,
    ``effectivity``, ``work-precision``; a figure without data is left out."""
    has_error = table["energy_error"].gt(0).any()
    y = "energy_error" if has_error else "eta"
    figures = {
        "convergence": _figure(table, "ndofs",
                               [("energy_error", ""), ("eta", " eta")] if has_error
                               else [("eta", " eta")], "ndofs", "error, eta"),
        "effectivity": _figure(table, "ndofs", [("effectivity_index", "")], "ndofs",
                               "eta / ||u - u_h||") if has_error else None,
        "work-precision": _figure(table, "time", [(y, "")],
                                  "cumulative wall time [s]", y,
                                  x_values=lambda group: phase_time(group).cumsum()),
    }
    return {suffix: fig.to_html(full_html=False, include_plotlyjs=False,
                                div_id=file_stem(scene, suffix), config={"displaylogo": False})
            for suffix, fig in figures.items() if fig is not None}

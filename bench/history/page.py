"""The static page of the history (docs/history.md): per source, every figure's value over the
last PAGE_COMMITS commits relative to its latest value (the moved ones red, the floor of their
kind's noise band shaded), and the table of values with each figure's band and the moves of
the last commit."""

from __future__ import annotations

import base64
import html
import io
from pathlib import Path

import pandas as pd
from matplotlib.figure import Figure as Canvas

from bench.history.moves import FLOORS, moves
from bench.history.store import commit_order
from bench.matrix.files import atomic_text

PAGE_COMMITS = 10


def source_figure(frame: pd.DataFrame, commits: list[str], moved: set[str]) -> str:
    """A PNG (base64) of the source's figures over ``commits``, each divided by its last."""
    canvas = Canvas(figsize=(9, 3.6))
    axes = canvas.subplots()
    position = {c: k for k, c in enumerate(commits)}
    for name, group in frame.groupby("name"):
        group = group[group["commit"].isin(position)].sort_values(
            "commit", key=lambda c: c.map(position))
        if group.empty or not group["value"].iloc[-1]:  # nothing shown, or no scale
            continue
        last = group["value"].iloc[-1]
        axes.plot(group["commit"].map(position), group["value"] / last,
                  color="tab:red" if name in moved else "0.6",
                  linewidth=1.4 if name in moved else 0.6, zorder=3 if name in moved else 2)
    floor = max(FLOORS[k] for k in frame["kind"].unique())
    axes.axhspan(1 - floor, 1 + floor, color="0.9", zorder=1)
    axes.set_xticks(range(len(commits)), [c[:7] for c in commits], rotation=45, fontsize=7)
    axes.set_ylabel("value / latest value")
    canvas.tight_layout()
    buffer = io.BytesIO()
    canvas.savefig(buffer, format="png", dpi=90)
    return base64.b64encode(buffer.getvalue()).decode("ascii")


def source_table(frame: pd.DataFrame, commits: list[str], bands: dict) -> str:
    wide = frame[frame["commit"].isin(commits)].pivot_table(
        index="name", columns="commit", values="value", aggfunc="last")
    wide = wide.reindex(columns=[c for c in commits if c in wide.columns])
    wide.columns = [c[:7] for c in wide.columns]
    wide["band"] = [bands.get(name, float("nan")) for name in wide.index]
    return wide.to_html(float_format=lambda v: f"{v:.4g}", na_rep="", escape=True)


def write_page(history: pd.DataFrame, out: str | Path) -> Path:
    """OUT/index.html: every source's figure and table over the last PAGE_COMMITS commits."""
    out = Path(out)
    commits = commit_order(history)[-PAGE_COMMITS:]
    last = moves(history)
    moved = {(m.source, m.name) for m in last if m.moved}
    bands = {(m.source, m.name): m.band for m in last}
    parts = [f"<h1>signorini-bench: the history of its figures</h1><p>{len(commits)} "
             f"commits, {history['name'].nunique()} figures; moved beyond their noise at the "
             f"last commit: {len(moved)}.</p>"]
    if moved:
        parts.append("<ul>" + "".join(f"<li>{html.escape(m.line())}</li>"
                                      for m in last if m.moved) + "</ul>")
    for source, frame in history.groupby("source", sort=True):
        names = {n for s, n in moved if s == source}
        image = source_figure(frame, commits, names)
        parts.append(f"<h2>{html.escape(source)}</h2><img alt='{html.escape(source)}' "
                     f"src='data:image/png;base64,{image}'>")
        parts.append(source_table(frame, commits, {n: b for (s, n), b in bands.items()
                                                   if s == source}))
    out.mkdir(parents=True, exist_ok=True)
    page = out / "index.html"
    atomic_text("<!doctype html><meta charset='utf-8'><title>history</title>"
                "<style>body{font-family:sans-serif;max-width:1100px;margin:auto}"
                "table{border-collapse:collapse;font-size:12px}td,th{border:1px solid #ccc;"
                "padding:2px 6px}</style>" + "".join(parts), page)
    return page

"""Where the figures of the history come from (docs/history.md): a registered source reads a
results folder of its command into ``Figure`` values; one function and one registration each.

* ``verify``: every gate's value per combination (``verdicts.csv`` of ``python -m bench
  verify --out DIR``), deterministic up to round-off;
* ``compare``: the default comparison's headline, per scene and target the cheapest
  combination's time (its noise: the measured gap to its second-best sample) and DOFs;
* ``scaling``: per size the fast contact solve against the linear solve, the solve's and the
  assembly's time and the peak memory (``scaling.csv`` of ``python -m bench scaling``).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path

import pandas as pd

from bench.history.store import Figure
from scenes.registry import Registry

SOURCES = Registry("history source")
# a gate's quantity -> the kind of figure it is
GATE_KINDS = {"rate": "rate", "effectivity": "effectivity", "error": "error", "ratio": "ratio",
              "misses": "count", "sign": "count", "levels": "count", "seconds": "time"}


def register_source(name: str, description: str):
    """Register ``read(folder) -> list[(name, value, kind, noise)]`` as source ``name``."""
    return SOURCES.register(name, description)


def figures_of(source: str, folder: str | Path, commit: str, recorded: str) -> list[Figure]:
    """The figures of ``folder`` read by ``source``, stamped with ``commit`` and ``recorded``."""
    read: Callable = SOURCES.get(source)
    folder = Path(folder)
    if not folder.is_dir():
        raise ValueError(f"{source}={str(folder)!r} is not a results folder")
    return [Figure(commit, recorded, source, name, float(value), kind, float(noise))
            for name, value, kind, noise in read(folder)]


def results_file(folder: Path, name: str, command: str) -> Path:
    """``folder/name``, or a one-line refusal naming the command that writes it."""
    path = folder / name
    if not path.exists():
        raise ValueError(f"{str(folder)!r} has no {name}: give a folder of "
                         f"python -m bench {command} --out")
    return path


def gate_kind(gate: str, quantity: str) -> str:
    """The kind of a gate's figure from its quantity's name (a count when nothing says)."""
    text = f"{quantity} {gate}".lower()
    return next((kind for word, kind in GATE_KINDS.items() if word in text), "count")


@register_source("verify", "every gate's value per combination (verdicts.csv of verify --out)")
def verify_figures(folder: Path) -> list[tuple]:
    frame = pd.read_csv(results_file(folder, "verdicts.csv", "verify"))
    frame = frame[pd.to_numeric(frame["value"], errors="coerce").notna()]
    return [(f"{row.gate} [{row.combination}]", float(row.value),
             gate_kind(row.gate, ""), math.nan) for row in frame.itertuples()]


@register_source("compare", "the default comparison's headline: per scene and target the "
                            "cheapest combination's time and DOFs")
def compare_figures(folder: Path) -> list[tuple]:
    from bench.matrix.store import read_results
    from bench.report.render import read_json
    from bench.report.summary import scene_answers

    table = read_results(folder)
    if table is None:
        raise ValueError(f"{str(folder)!r} holds no results")
    rows = table[table["level"] >= 0]
    out = []
    for answer in scene_answers(rows, read_json(folder, "truth.json"), folder):
        for ranking in answer.rankings:
            if ranking.ranked:
                best = ranking.ranked[0]
                where = f"{answer.scene} to {ranking.target:g}"
                out.append((f"{where}: seconds", best.seconds, "time",
                            max(best.high - best.seconds, 0.0)))
                out.append((f"{where}: DOFs", float(best.ndofs), "count", math.nan))
    run = read_json(folder, "run.json")
    if "seconds" in run:
        out.append(("wall time", float(run["seconds"]), "time", math.nan))
    return out


SCALING_FIGURES = (("fast_over_linear", "ratio"), ("t_fast_solve", "time"),
                   ("t_assemble", "time"), ("peak_gib", "memory"))


@register_source("scaling", "per size: the fast contact solve over the linear solve, the "
                            "solve's and the assembly's time, the peak memory")
def scaling_figures(folder: Path) -> list[tuple]:
    frame = pd.read_csv(results_file(folder, "scaling.csv", "scaling"))
    out = []
    for row in frame.to_dict("records"):
        size = (f"{row.get('dim', 2)}D P{row.get('order', 1)} {row.get('backend', '')} "
                f"{int(row['ndofs'])} DOFs")
        out += [(f"{size}: {column}", float(row[column]), kind, math.nan)
                for column, kind in SCALING_FIGURES if column in row
                and row[column] == row[column]]
    return out

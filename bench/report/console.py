"""The last lines ``compare`` and ``report`` print: at most MAX_LINES, where the report is, how
long it took, one headline per scene (from the verdict box) and the hard cases as counts plus
the rows that were not as expected (the README, "Reading the report")."""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from bench.hard import check_expected
from bench.report.summary import scene_answers
from bench.sequence.rows import with_labels
from bench.verify import load_expected

MAX_LINES = 10


def duration(seconds: float) -> str:
    """'7 min 12 s', '42.0 s'."""
    minutes, rest = divmod(float(seconds), 60.0)
    return f"{int(minutes)} min {rest:.0f} s" if minutes else f"{rest:.1f} s"


def sequences_text(table: pd.DataFrame) -> str:
    """'192 sequences (140 run, 52 combinations skipped)': every sequence of the table, and
    how many were whole-sequence rows that say why a combination cannot run."""
    every = table["sequence_key"].nunique()
    skipped = table.loc[(table["level"] < 0) & (table["status"] == "skipped"),
                        "sequence_key"].nunique()
    return (f"{every} sequences ({every - skipped} run, {skipped} combinations skipped)"
            if skipped else f"{every} sequences")


def hard_lines(hard: pd.DataFrame, room: int) -> list[str]:
    """The verdicts as counts, then the unexpected rows (as many as ``room`` allows)."""
    counts = ", ".join(f"{n} {v}" for v, n in hard["verdict"].value_counts().items())
    checks = check_expected(hard, load_expected().get("hard", []))
    wrong = [c for c in checks if not c["passed"]]
    lines = [f"hard cases: {counts}; {len(checks) - len(wrong)} of {len(checks)} as expected"]
    shown = wrong[:max(room - 1, 0)]
    lines += [f"  UNEXPECTED {c['case']}/{c['formulation']}/{c['solver']}/{c['variant']}: "
              f"{c['verdict']}, expected {c['expected']}" for c in shown]
    if len(wrong) > len(shown):
        lines[-1] += f" (and {len(wrong) - len(shown)} more in hard.md)"
    return lines


def console_summary(readme: Path, table: pd.DataFrame, hard: pd.DataFrame | None = None,
                    seconds: float | None = None, truth: dict | None = None,
                    results: Path | None = None) -> list[str]:
    """The last lines of ``compare`` (with its wall time) and ``report``; ``truth`` is the
    results' truth.json (the scale of relative errors), ``results`` the folder (its
    timings)."""
    readme = Path(readme)
    lines = [f"report: {readme.parent / 'index.html'} (open in a browser), {readme}"]
    rows = with_labels(table)
    rows = rows[rows["level"] >= 0]
    if seconds is not None:
        lines.append(f"{len(table)} rows in {sequences_text(table)}; wall time "
                     f"{duration(seconds)}")
    lines += [answer.sentence for answer in scene_answers(rows, truth or {}, results)]
    if hard is not None and len(hard):
        lines += hard_lines(hard, MAX_LINES - len(lines))
    return lines[:MAX_LINES]

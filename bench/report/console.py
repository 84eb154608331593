"""The last lines ``compare`` and ``report`` print: at most MAX_LINES, where the report is, how
long it took, one headline per scene and the hard cases as counts plus the rows that were not
as expected (the README, "Reading the report")."""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from bench.hard import check_expected
from bench.report.summary import effectivity_ranges, fastest, sig3
from bench.sequence.rows import with_labels
from bench.verify import load_expected

MAX_LINES = 10


def duration(seconds: float) -> str:
    """'7 min 12 s', '42.0 s'."""
    minutes, rest = divmod(float(seconds), 60.0)
    return f"{int(minutes)} min {rest:.0f} s" if minutes else f"{rest:.1f} s"


def headline(scene: str, group: pd.DataFrame) -> str:
    """The scene's first combination to the report's target accuracy, and the estimators'
    effectivity ranges."""
    best = fastest(group)
    top = best["ranking"][0] if best["ranking"] else None
    measure = "error" if best["column"] == "energy_error" else "eta"
    first = (f"{top['combination']} P{top['order']} first to {measure} "
             f"{sig3(best['target'])} ({sig3(top['seconds'])} s)" if top
             else "no combination reached the target")
    return f"{scene}: {first}; effectivity {effectivity_ranges(group)}"


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
                    seconds: float | None = None) -> list[str]:
    """The last lines of ``compare`` (with its wall time) and ``report``."""
    readme = Path(readme)
    lines = [f"report: {readme.parent / 'index.html'} (open in a browser), {readme}"]
    rows = with_labels(table)
    rows = rows[rows["level"] >= 0]
    if seconds is not None:
        lines.append(f"{len(table)} rows, {rows['sequence_key'].nunique()} sequences; "
                     f"wall time {duration(seconds)}")
    for scene, group in rows.groupby("scene", sort=True):
        lines.append(headline(scene, group))
    if hard is not None and len(hard):
        lines += hard_lines(hard, MAX_LINES - len(lines))
    return lines[:MAX_LINES]

"""The default comparison's figures for the README, written between its ``compare`` markers by
``python -m bench compare --readme README.md``, so that every count there comes from a run."""

from __future__ import annotations

import platform
from pathlib import Path

import pandas as pd

from bench.hard import check_expected
from bench.matrix.cost import read_timings
from bench.matrix.store import read_results
from bench.perf.scaling import replace_in_readme
from bench.report.console import sequences_text
from bench.report.ranking import spread_text
from bench.report.render import read_json
from bench.report.summary import scene_answers
from bench.verify import load_expected

README_START, README_END = "<!-- compare:start -->", "<!-- compare:end -->"


def compare_block(table: pd.DataFrame, hard: pd.DataFrame | None, seconds: float,
                  results: Path | None = None) -> str:
    """One Markdown paragraph (rows by status, sequences, hard verdicts and wall time), then the
    recommendation per scene and the measured timing spread when ``results`` is given."""
    statuses = table["status"].value_counts()
    by_status = ", ".join(f"{statuses[s]} {s}" for s in sorted(statuses.index))
    text = (f"Last `python -m bench compare` on this machine ({platform.machine()}, Python "
            f"{platform.python_version()}): **{len(table)} result rows** ({by_status}) in "
            f"{sequences_text(table)}")
    if hard is not None:
        checks = check_expected(hard, load_expected().get("hard", []))
        passed = sum(c["passed"] for c in checks)
        text += f"; {passed} of {len(checks)} hard verdicts as expected"
    text += f"; {seconds:.0f} s wall time in all (references, run, timings, hard cases, report)."
    if results is None:
        return text
    truth = read_json(Path(results), "truth.json")
    rows = table[table["level"] >= 0]
    sentences = [f"- {a.sentence}" for a in scene_answers(rows, truth, Path(results))]
    spread = spread_text(read_timings(results))
    return "\n".join([text, "", *sentences, "", spread[0].upper() + spread[1:] + "."])


def write_compare_block(readme: str | Path, results: str | Path, seconds: float) -> None:
    """Replace the README's compare block with the figures of the results folder."""
    hard_csv = Path(results) / "hard.csv"
    hard = pd.read_csv(hard_csv) if hard_csv.exists() else None
    replace_in_readme(readme, README_START, README_END,
                      compare_block(read_results(results), hard, seconds, Path(results)))


def check_readme(readme: str | Path) -> None:
    """Refuse, before the comparison runs, a README that cannot take the block."""
    path = Path(readme)
    text = path.read_text() if path.is_file() else ""
    if README_START not in text or README_END not in text:
        raise ValueError(f"--readme={str(readme)!r} is not a file with the markers "
                         f"{README_START} ... {README_END}")

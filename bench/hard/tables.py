"""The hard cases' table: each row's verdict against its expected one (``[[hard]]`` in
``bench/verify/expected.toml``), its display and its files."""

from __future__ import annotations

import fnmatch
from pathlib import Path

import pandas as pd

from bench.hard.verdicts import ACCURATE
from bench.matrix.files import atomic_text, atomic_write


def cell_text(value) -> str:
    """A hard table cell as an entry matches it: "" for NaN, integers without a decimal."""
    if value is None or pd.isna(value):
        return ""
    if isinstance(value, float) and value.is_integer():
        return str(int(value))
    return str(value)


def check_expected(table: pd.DataFrame, expected: list[dict]) -> list[dict]:
    """Each row's verdict against the first matching [[hard]] entry (default: accurate),
    matched by case, formulation, solver, variant and ndofs (shell patterns, each "*" when
    left out); an entry's verdict may list alternatives, "accurate|inaccurate", for a
    borderline case. A skipped row (cells that cannot carry the scene) judges no solve and is
    not checked."""
    out = []
    for _, row in table.iterrows():
        if row.get("status") == "skipped":
            continue
        want, source = ACCURATE, "default: every solve accurate"
        for entry in expected:
            if all(fnmatch.fnmatch(cell_text(row.get(k)), str(entry.get(k, "*")))
                   for k in ("case", "formulation", "solver", "variant", "ndofs")):
                want, source = entry["verdict"], entry["source"]
                break
        out.append({"case": row["case"], "formulation": row["formulation"],
                    "solver": row["solver"], "variant": row["variant"],
                    "verdict": row["verdict"], "expected": want,
                    "passed": row["verdict"] in want.split("|"), "source": source})
    return out


SUMMARY = ["case", "formulation", "solver", "variant", "ndofs", "status", "safeguard",
           "iterations", "loss", "pressure_loss", "condition_estimate", "inf_sup",
           "pressure_oscillation", "discretisation", "verdict", "finding"]


def hard_display(table: pd.DataFrame) -> pd.DataFrame:
    """The verdict table as strings (the report's and the CLI's), numbers to 3 digits."""
    shown = table.reindex(columns=SUMMARY).copy()
    for column in ("loss", "pressure_loss", "condition_estimate", "inf_sup",
                   "pressure_oscillation"):
        shown[column] = shown[column].map(lambda v: "" if pd.isna(v) else f"{v:.3g}")
    for column in ("ndofs", "iterations"):
        shown[column] = shown[column].map(lambda v: "" if pd.isna(v) else f"{int(v)}")
    return shown.astype(object).where(shown.notna(), "").astype(str)


def hard_markdown(table: pd.DataFrame) -> str:
    return hard_display(table).to_markdown(index=False)


def write_hard(table: pd.DataFrame, out) -> Path:
    """``out/hard.csv`` (every column) and ``out/hard.md`` (the verdict table)."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    atomic_write(table, out / "hard.csv", "csv")
    atomic_text(hard_markdown(table) + "\n", out / "hard.md")
    return out / "hard.csv"

"""The result store: ``results.csv`` and ``results.parquet`` in an output folder.

Every finished row is written immediately (CSV appended, parquet rewritten atomically), so an
interrupted run loses no finished result. Rows of earlier runs in the same folder are kept
(``run_id`` tells runs apart) unless ``overwrite`` is set.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import pandas as pd

from bench.sequence.rows import COLUMNS, ResultRow


class ResultsError(ValueError):
    """A results table that cannot be read."""


def read_results(folder: str | Path) -> pd.DataFrame | None:
    """The rows of ``folder/results.parquet`` (None if there is none). An unreadable parquet
    falls back to the CSV mirror when that is intact (with a note on standard error); when
    both are unreadable, ResultsError names the file and what to do."""
    folder = Path(folder)
    parquet, csv = folder / "results.parquet", folder / "results.csv"
    if not parquet.exists():
        return None
    try:
        return pd.read_parquet(parquet)
    except Exception as error:  # pyarrow raises several types for a damaged file
        why = f"{parquet} is unreadable ({type(error).__name__}: {error})"
    try:
        table = pd.read_csv(csv)
        if "scene" not in table.columns or "level" not in table.columns:
            raise ValueError("not a results table")
    except Exception as error:
        raise ResultsError(f"{why}, and so is its CSV mirror {csv} ({error}); move the folder "
                           "away or rerun with --overwrite") from None
    print(f"note: {why}; using its CSV mirror {csv} ({len(table)} rows)", file=sys.stderr)
    return table


class ResultStore:
    def __init__(self, out: str | Path, overwrite: bool = False):
        self.out = Path(out)
        self.out.mkdir(parents=True, exist_ok=True)
        self.csv, self.parquet = self.out / "results.csv", self.out / "results.parquet"
        if overwrite:
            for path in (self.csv, self.parquet):
                path.unlink(missing_ok=True)
        self.previous = read_results(self.out)
        if self.previous is not None and list(self.previous.columns) != COLUMNS:
            # written by a version with fewer columns: new columns are added, never renamed
            self.previous = self.previous.reindex(columns=COLUMNS)
            self.previous.to_csv(self.csv, index=False)
        self.rows: list[dict] = []

    def append(self, row: ResultRow) -> None:
        self.rows.append(row.as_dict())
        frame = pd.DataFrame([row.as_dict()], columns=COLUMNS)
        frame.to_csv(self.csv, mode="a", header=not self.csv.exists(), index=False)
        tmp = self.parquet.with_suffix(".parquet.tmp")
        self.table().to_parquet(tmp, index=False)
        os.replace(tmp, self.parquet)

    def table(self) -> pd.DataFrame:
        """All rows in the folder: earlier runs, then this run's."""
        current = pd.DataFrame(self.rows, columns=COLUMNS)
        if self.previous is None or self.previous.empty:
            return current
        return pd.concat([self.previous, current], ignore_index=True)

    def run_table(self) -> pd.DataFrame:
        """This run's rows only."""
        return pd.DataFrame(self.rows, columns=COLUMNS)

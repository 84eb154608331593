"""The result store of an output folder: one partition per sequence, and the consolidated
``results.parquet`` and ``results.csv`` derived from them.

Each sequence writes only its own partition, ``sequences/<sequence key>.parquet``, rewritten
atomically (a temporary file of the writing process, then a rename) after every finished level,
so concurrent runs and Dask workers never write the same file and an interrupted run loses no
finished level. ``consolidate`` rebuilds the two tables from all partitions under a file lock,
each atomically: no row is lost or duplicated, and a rerun of a sequence replaces its own
partition. Rows of earlier runs are kept unless ``overwrite`` is set; a folder written by an
older version (tables, no partitions) is taken over as one partition.
"""

from __future__ import annotations

import fcntl
import hashlib
import io
import os
import shutil
import sys
from contextlib import contextmanager
from pathlib import Path

import pandas as pd

from bench.sequence.rows import COLUMNS, FINISHED, ResultRow, with_labels


class ResultsError(ValueError):
    """A results table that cannot be read."""


def read_results(folder: str | Path) -> pd.DataFrame | None:
    """The rows of ``folder`` (None if it has none). The partitions in ``sequences/`` are the
    source of truth: when ``results.parquet`` is missing, unreadable or holds other rows than
    they do, both tables are rebuilt from them (with a note on standard error). Without
    partitions, an unreadable parquet falls back to the CSV mirror when that is intact; when
    both are unreadable, ResultsError names the file and what to do."""
    folder = Path(folder)
    parquet, csv = folder / "results.parquet", folder / "results.csv"
    partitions = folder / "sequences"
    if any(partitions.glob("*.parquet")):
        return _rebuilt_if_stale(folder)
    if not parquet.exists():
        return None
    try:
        return read_snapshot(parquet)
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


def _rebuilt_if_stale(folder: Path) -> pd.DataFrame:
    """The consolidated table of ``folder``'s partitions; the tables on disk are rewritten
    from them if they are missing, unreadable or differ in their rows."""
    parquet, csv = folder / "results.parquet", folder / "results.csv"
    table = partition_table(folder / "sequences")
    try:
        on_disk = read_snapshot(parquet)
        csv_rows = len(pd.read_csv(csv, usecols=["sequence_key"]))
        why = None if len(on_disk) == len(table) == csv_rows and \
            set(on_disk["sequence_key"]) == set(table["sequence_key"]) else \
            f"{parquet} or {csv.name} holds other rows than the partitions"
    except Exception as error:  # missing or damaged: pyarrow and pandas raise several types
        why = f"{parquet} or {csv.name} is missing or unreadable " \
              f"({type(error).__name__}: {error})"
    if why is None:
        return on_disk
    store = ResultStore(folder)
    table = store.consolidate().reset_index(drop=True)
    print(f"note: {why}; rebuilt both from the partitions in {store.partitions} "
          f"({len(table)} rows)", file=sys.stderr)
    return table


def partition_table(partitions: Path) -> pd.DataFrame:
    """Every row of the partitions ``partitions/*.parquet``, with every column."""
    frames = [read_snapshot(path) for path in sorted(partitions.glob("*.parquet"))]
    frames = [f for f in frames if len(f)]
    if not frames:
        return pd.DataFrame(columns=COLUMNS)
    return with_labels(pd.concat(frames, ignore_index=True).reindex(columns=COLUMNS))


def read_snapshot(path: Path) -> pd.DataFrame:
    """A parquet file read from one open: pyarrow opens a path again for its pages after the
    footer, so a file replaced in between by another writer would be read half old, half new."""
    return pd.read_parquet(io.BytesIO(path.read_bytes()))


def atomic_write(frame: pd.DataFrame, path: Path, kind: str) -> None:
    """Write ``frame`` to ``path`` as parquet or csv through a temporary file of this process."""
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    if kind == "parquet":
        frame.to_parquet(tmp, index=False)
    else:
        frame.to_csv(tmp, index=False)
    os.replace(tmp, path)


@contextmanager
def folder_lock(folder: Path):
    """An exclusive lock on ``folder`` (a lock file in it) across processes."""
    with open(folder / ".lock", "a") as handle:
        fcntl.flock(handle, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(handle, fcntl.LOCK_UN)


class SequenceWriter:
    """The partition of one sequence: every row as it finishes, then its end reason."""

    def __init__(self, path: Path):
        self.path, self.rows = path, []

    def append(self, row: ResultRow) -> None:
        self.rows.append(row.as_dict())
        self._write()

    def finish(self, end: str) -> None:
        for row in self.rows:
            row["sequence_end"] = end
        self._write()

    def _write(self) -> None:
        atomic_write(pd.DataFrame(self.rows, columns=COLUMNS), self.path, "parquet")


class ResultStore:
    def __init__(self, out: str | Path, overwrite: bool = False):
        self.out = Path(out)
        self.out.mkdir(parents=True, exist_ok=True)
        self.csv, self.parquet = self.out / "results.csv", self.out / "results.parquet"
        self.partitions = self.out / "sequences"
        with folder_lock(self.out):
            if overwrite:
                for path in (self.csv, self.parquet):
                    path.unlink(missing_ok=True)
                shutil.rmtree(self.partitions, ignore_errors=True)
            self.partitions.mkdir(exist_ok=True)
            self._adopt_tables()
        self.writers: dict[str, SequenceWriter] = {}

    def _adopt_tables(self) -> None:
        """Tables without partitions (an older version wrote them) become one partition."""
        if any(self.partitions.glob("*.parquet")):
            return
        previous = read_results(self.out)
        if previous is not None and len(previous):
            digest = hashlib.sha256(previous.to_csv().encode()).hexdigest()[:12]
            frame = with_labels(previous.reindex(columns=COLUMNS))
            atomic_write(frame, self.partitions / f"adopted-{digest}.parquet", "parquet")

    def sequence(self, key: str) -> SequenceWriter:
        return SequenceWriter(self.partitions / f"{key}.parquet")

    def append(self, row: ResultRow) -> None:
        """Store one finished row in its sequence's partition and consolidate."""
        key = row.sequence_key or "unkeyed"
        if key not in self.writers:
            self.writers[key] = self.sequence(key)
        self.writers[key].append(row)
        self.consolidate()

    def finish(self, key: str, end: str) -> None:
        """Record why the sequence ``key`` ended, in its partition."""
        if key in self.writers:
            self.writers[key].finish(end)
        self.consolidate()

    def table(self) -> pd.DataFrame:
        """All rows in the folder, from every partition: earlier runs and this run's."""
        return partition_table(self.partitions)

    def consolidate(self) -> pd.DataFrame:
        """results.parquet and results.csv from every partition (under the folder's lock)."""
        with folder_lock(self.out):
            table = self.table().sort_values(["run_id"], kind="stable")
            atomic_write(table, self.parquet, "parquet")
            atomic_write(table, self.csv, "csv")
        return table

    def finished_keys(self) -> set[str]:
        """Keys of the sequences in this folder that ended (not cut short): a rerun with the
        same spec reuses them."""
        table = self.table()
        done = table[table["sequence_end"].isin(FINISHED)]
        return set(done["sequence_key"]) - {""}

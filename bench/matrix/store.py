"""The result store of an output folder: one partition per sequence, and the consolidated
``results.parquet`` and ``results.csv`` derived from them.

Each sequence writes only its own partition, ``sequences/<sequence key>.parquet``, rewritten
atomically (a temporary file of the writing process, then a rename) after every finished level,
so concurrent runs and Dask workers never write the same file and an interrupted run loses no
finished level. ``consolidate`` (when a sequence ends) rebuilds the two tables from all
partitions under a file lock,
each atomically: no row is lost or duplicated, and a rerun of a sequence replaces its own
partition. Rows of earlier runs are kept unless ``overwrite`` is set; a folder written by an
older version (tables, no partitions) is taken over as one partition.
"""

from __future__ import annotations

import fcntl
import hashlib
import json
import os
import shutil
import sys
import time
from contextlib import contextmanager
from pathlib import Path

import pandas as pd

from bench.matrix.files import (
    atomic_write,
    checksums,
    read_partition,
    read_snapshot,
)
from bench.sequence.rows import COLUMNS, FINISHED, ResultRow, with_labels

MANIFEST = "results.sha256"  # checksums of the partitions and tables at consolidation


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
    """The consolidated table of ``folder``'s partitions. The tables on disk are trusted only
    when the checksums recorded at their consolidation (``results.sha256``) still match every
    partition and both tables; else both are rewritten from the partitions."""
    parquet, csv = folder / "results.parquet", folder / "results.csv"
    table = partition_table(folder / "sequences")
    why = None
    try:
        recorded = json.loads((folder / MANIFEST).read_text())
        if recorded != checksums(folder):
            why = f"{parquet.name} or {csv.name} holds other rows than the partitions"
        else:
            on_disk = read_snapshot(parquet)
    except Exception as error:  # missing or damaged: json, pyarrow raise several types
        why = f"{parquet} or {csv.name} (or its checksums {MANIFEST}) is missing or " \
              f"unreadable ({type(error).__name__}: {error})"
    if why is None:
        return on_disk
    store = ResultStore(folder)
    table = store.consolidate().reset_index(drop=True)
    print(f"note: {why}; rebuilt both from the partitions in {store.partitions} "
          f"({len(table)} rows)", file=sys.stderr)
    return table


def partition_table(partitions: Path) -> pd.DataFrame:
    """Every row of the partitions ``partitions/*.parquet``, with every column; a damaged
    partition is restored from the folder's tables or set aside (``read_partition``)."""
    frames = [read_partition(path) for path in sorted(partitions.glob("*.parquet"))]
    frames = [f for f in frames if f is not None and len(f)]
    if not frames:
        return pd.DataFrame(columns=COLUMNS)
    return with_labels(pd.concat(frames, ignore_index=True).reindex(columns=COLUMNS))


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
    """The store of one output folder. With ``overwrite`` the earlier results are moved aside
    (``.previous-*``), not deleted: ``keep_new`` deletes them once the new run has finished a
    sequence, ``restore_previous`` puts them back when it fails before that."""

    PREVIOUS = ".previous-"  # prefix of the folder that holds results moved aside
    MOVED = ("results.parquet", "results.csv", "rates.csv", "rates.md", "sequences")

    def __init__(self, out: str | Path, overwrite: bool = False):
        self.out = Path(out)
        self.out.mkdir(parents=True, exist_ok=True)
        self.csv, self.parquet = self.out / "results.csv", self.out / "results.parquet"
        self.partitions = self.out / "sequences"
        self.previous: Path | None = None
        with folder_lock(self.out):
            self._note_leftovers()
            if overwrite:
                self._move_aside()
            self.partitions.mkdir(exist_ok=True)
            self._adopt_tables()
        self.writers: dict[str, SequenceWriter] = {}

    def _note_leftovers(self) -> None:
        for folder in sorted(self.out.glob(f"{self.PREVIOUS}*")):
            print(f"note: {folder} holds results that an earlier --overwrite run moved aside "
                  "and did not finish replacing; move its files back into "
                  f"{self.out} to keep them, or delete it", file=sys.stderr)

    def _move_aside(self) -> None:
        present = [name for name in self.MOVED if (self.out / name).exists()]
        if not present:
            return
        self.previous = self.out / f"{self.PREVIOUS}{os.getpid()}-{time.time_ns()}"
        self.previous.mkdir()
        for name in present:
            os.replace(self.out / name, self.previous / name)

    def keep_new(self) -> None:
        """The new run has finished a sequence: the results moved aside are deleted."""
        if self.previous is not None:
            shutil.rmtree(self.previous, ignore_errors=True)
            self.previous = None

    def restore_previous(self) -> None:
        """The new run failed before finishing a sequence: the results moved aside come back
        (the new run's own partitions, rows it finished, are kept beside them)."""
        if self.previous is None:
            return
        with folder_lock(self.out):
            self.partitions.mkdir(exist_ok=True)
            for path in sorted(self.previous.glob("sequences/*.parquet")):
                if not (self.partitions / path.name).exists():
                    os.replace(path, self.partitions / path.name)
            for name in ("rates.csv", "rates.md"):
                if (self.previous / name).exists() and not (self.out / name).exists():
                    os.replace(self.previous / name, self.out / name)
            if not (self.previous / "sequences").exists():  # tables of an older version
                self._adopt(read_results(self.previous))
            shutil.rmtree(self.previous, ignore_errors=True)
            self.previous = None
        self.consolidate()

    def _adopt_tables(self) -> None:
        """Tables without partitions (an older version wrote them) become one partition."""
        if not any(self.partitions.glob("*.parquet")):
            self._adopt(read_results(self.out))

    def _adopt(self, previous: pd.DataFrame | None) -> None:
        if previous is not None and len(previous):
            digest = hashlib.sha256(previous.to_csv().encode()).hexdigest()[:12]
            frame = with_labels(previous.reindex(columns=COLUMNS))
            atomic_write(frame, self.partitions / f"adopted-{digest}.parquet", "parquet")

    def sequence(self, key: str) -> SequenceWriter:
        return SequenceWriter(self.partitions / f"{key}.parquet")

    def append(self, row: ResultRow) -> None:
        """Store one finished row in its sequence's partition, the durable record; the tables
        are consolidated when the sequence ends (``finish``). Consolidating after every row
        re-read every partition each time, quadratic in the run; meanwhile a reader finds the
        tables stale by their checksums and rebuilds them (``read_results``)."""
        key = row.sequence_key or "unkeyed"
        if key not in self.writers:
            self.writers[key] = self.sequence(key)
        self.writers[key].append(row)

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
            # partitions' checksums first: one that a worker replaces meanwhile then fails
            # them, and the tables are rebuilt when next read (never trusted while stale)
            before = checksums(self.out, tables=False)
            table = self.table().sort_values(["run_id"], kind="stable")
            atomic_write(table, self.parquet, "parquet")
            atomic_write(table, self.csv, "csv")
            written = {**before, **{path.name: hashlib.sha256(path.read_bytes()).hexdigest()
                                    for path in (self.parquet, self.csv)}}
            manifest = self.out / f".{MANIFEST}.{os.getpid()}.tmp"
            manifest.write_text(json.dumps(written, indent=1))
            os.replace(manifest, self.out / MANIFEST)
        return table

    def finished_keys(self) -> set[str]:
        """Keys of the sequences in this folder that ended (not cut short): a rerun with the
        same spec reuses them."""
        table = self.table()
        done = table[table["sequence_end"].isin(FINISHED)]
        return set(done["sequence_key"]) - {""}

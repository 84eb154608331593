"""The result store of an output folder (docs/reliability.md, "The store"): one partition per
sequence, the record, and the consolidated ``results.parquet`` and ``results.csv`` derived
from them.

Each sequence writes only its own partition, ``sequences/<sequence key>.parquet``, whole or not
at all (``files.atomic_write``) after every finished level, so concurrent runs and Dask workers
never write the same file and an ended process loses no finished level. ``consolidate`` (every
CONSOLIDATE_SECONDS while a run lasts, as its sequences end, and at its end) rewrites the two
tables from all partitions under a file lock. Readers
(``read_results``: ``report``, ``diff``, ``compare``'s report) never write into a folder; the
writer repairs what ``FolderState`` found when it opens the folder: a set-aside folder whose run
has ended comes back, rows the tables hold and the partitions lost become partitions again, a
damaged partition is set aside."""

from __future__ import annotations

import fcntl
import hashlib
import json
import os
import sys
import time
from contextlib import contextmanager
from pathlib import Path

import pandas as pd

from bench.matrix.files import (
    abandoned_temporaries,
    atomic_text,
    atomic_write,
    checksums,
    read_snapshot,
)
from bench.matrix.folder_state import MANIFEST, FolderState, read_partitions, table_of
from bench.matrix.set_aside import SetAsideFolder, discard, discard_folder, restore_into
from bench.sequence.rows import COLUMNS, FINISHED, ResultRow, with_labels

CONSOLIDATE_SECONDS = 30.0  # how often a run refreshes its tables from the partitions


class ResultsError(ValueError):
    """A results table that cannot be read."""


def read_results(folder: str | Path) -> pd.DataFrame | None:
    """The rows of ``folder`` (None if it has none), read without writing: the partitions in
    ``sequences/`` and what the tables or a set-aside folder hold beyond them (each counted in
    one note on standard error). Without partitions (an older version's folder) the table,
    or its CSV mirror when the parquet is unreadable; ResultsError when neither can be read."""
    folder = Path(folder)
    state = FolderState.read(folder, shared=True)
    if state.partitions or state.damaged or state.set_aside:
        if state.tables_current() and state.table is not None:
            return state.table
        for line in notes(state) or [stale_note(folder)]:
            print(line, file=sys.stderr)
        return state.rows()
    parquet, csv = folder / "results.parquet", folder / "results.csv"
    if not parquet.exists() and not csv.exists():
        return None
    if state.table is None:
        raise ResultsError(f"{parquet} is unreadable, and so is its CSV mirror {csv}; move the "
                           "folder away or rerun with --overwrite")
    if not _parquet_readable(parquet):
        print(f"note: {parquet} is unreadable; using its CSV mirror {csv} "
              f"({len(state.table)} rows)", file=sys.stderr)
    return state.table


def _parquet_readable(path: Path) -> bool:
    try:
        read_snapshot(path)
        return True
    except Exception:  # pyarrow raises several types for a damaged file
        return False


def notes(state: FolderState, writing: bool = False) -> list[str]:
    """One line for each way the folder differs from its record, with the rows it keeps
    (``writing``: as the writer that repairs it says it)."""
    folder, lines = state.folder, []
    kept = "they are written back" if writing else \
        f"they are kept (the next run into {folder} writes them back)"
    orphans = state.orphans()
    by_key = orphans["sequence_key"].astype(str) if len(orphans) else pd.Series(dtype=str)
    for path in state.damaged:
        held = int((by_key == path.stem).sum())
        lines.append(f"note: {path} is unreadable; its {held} rows are in the folder's results "
                     f"table: {kept}" if held else
                     f"warning: {path} is unreadable, and the folder's tables do not hold its "
                     f"rows; " + (f"set aside as {path.name}.damaged: this run reruns its "
                                  "sequence" if writing else
                                  f"left out (the next run into {folder} sets it aside and "
                                  "reruns its sequence)"))
    missing = orphans[~by_key.isin({p.stem for p in state.damaged})]
    if len(missing):
        count = missing["sequence_key"].nunique()
        lines.append(f"note: the results table holds {len(missing)} rows of {count} "
                     f"sequence{'s' if count != 1 else ''} whose files are missing from "
                     f"{folder / 'sequences'}; {kept}")
    for aside in state.set_aside:
        taken = [f for stem, f in state.restored() if stem in aside.partitions]
        if taken and not aside.alive:
            lines.append(f"note: {aside.path} holds {sum(map(len, taken))} rows of "
                         f"{len(taken)} sequence{'s' if len(taken) != 1 else ''} that an "
                         "--overwrite run set aside and did not "
                         f"replace (it ended before finishing a sequence); "
                         + ("they are put back" if writing else
                            f"they are kept (the next run into {folder} puts them back)"))
    return lines


def stale_note(folder: Path) -> str:
    return (f"note: {folder / 'results.parquet'} or results.csv holds other rows than the "
            f"partitions (or is missing); read from the partitions (the next run into {folder} "
            "rewrites both)")


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
    """The partition of one sequence: every row as it finishes, then its end reason. A rerun
    of a sequence cut short carries the earlier attempt's levels beyond its own until it
    passes them, so that a rerun cut shorter still loses no level (docs/reliability.md, "What
    finished means"); once the sequence ends they go."""

    def __init__(self, path: Path):
        self.path, self.rows = path, []
        self.carried = _earlier_attempt(path)

    def append(self, row: ResultRow) -> None:
        self.rows.append(row.as_dict())
        self._write()

    def finish(self, end: str) -> None:
        for row in self.rows:
            row["sequence_end"] = end
        if end in FINISHED:
            self.carried = []
        self._write()

    def _write(self) -> None:
        reached = max((row["level"] for row in self.rows), default=-1)
        rows = self.rows + [row for row in self.carried if row["level"] > reached]
        atomic_write(pd.DataFrame(rows, columns=COLUMNS), self.path, "parquet")


def _earlier_attempt(path: Path) -> list[dict]:
    """The rows of a partition at ``path`` whose sequence was cut short (none if it finished
    or cannot be read: a finished one is never rerun, a damaged one is set aside)."""
    try:
        frame = read_snapshot(path)
    except Exception:  # missing, or damaged (pyarrow raises several types)
        return []
    if frame["sequence_end"].isin(FINISHED).all():
        return []
    return frame.reindex(columns=COLUMNS).to_dict("records")


class ResultStore:
    """The store of one output folder, repaired when opened (``repair``). With ``overwrite``
    the earlier results are set aside (``set_aside.SetAsideFolder``), not deleted: ``keep_new``
    deletes them once the new run has finished a sequence, ``restore_previous`` puts them back
    when it ends before that (and the next run does, if the process was killed)."""

    def __init__(self, out: str | Path, overwrite: bool = False):
        self.out = Path(out)
        self.out.mkdir(parents=True, exist_ok=True)
        self.csv, self.parquet = self.out / "results.csv", self.out / "results.parquet"
        self.partitions = self.out / "sequences"
        self.previous: SetAsideFolder | None = None
        with folder_lock(self.out):
            self.partitions.mkdir(exist_ok=True)
            self.repair()
            if overwrite:
                self.previous = SetAsideFolder.create(self.out)
                self.partitions.mkdir(exist_ok=True)
        self.writers: dict[str, SequenceWriter] = {}
        self.consolidated_at = time.monotonic()

    def repair(self) -> None:
        """Make the record hold every row the folder holds: set-aside folders whose run has
        ended come back, a damaged partition is set aside (``*.damaged``), and rows that only
        the tables hold become partitions again; each said in one line."""
        state = FolderState.read(self.out)
        found = notes(state, writing=True)
        for line in found:
            print(line, file=sys.stderr)
        ended = [aside.path for aside in state.set_aside if not aside.alive]
        for path in ended:
            restore_into(self.out, path, state)
        for path in state.damaged:
            os.replace(path, path.with_name(path.name + ".damaged"))
        self._adopt(state.orphans())
        for path in ended:
            discard_folder(path)
        discard(self.out)
        for path in abandoned_temporaries(self.out):
            path.unlink(missing_ok=True)
        if found:
            self.consolidate(locked=True)

    def keep_new(self) -> None:
        """The new run has finished a sequence: the results set aside are deleted."""
        if self.previous is not None:
            self.previous.discard()
            self.previous = None

    def restore_previous(self) -> None:
        """The new run ended before finishing a sequence: the results set aside come back (the
        new run's own partitions, rows it finished, are kept beside them)."""
        if self.previous is None:
            return
        with folder_lock(self.out):
            restore_into(self.out, self.previous.path, FolderState.read(self.out))
            self._adopt(FolderState.read(self.out).orphans())
            self.previous.discard()
            self.previous = None
            self.consolidate(locked=True)

    def _adopt(self, rows: pd.DataFrame) -> None:
        """Rows that only a table holds, written back as one partition per sequence (those of
        an older version, without a key, as one ``adopted-*`` partition)."""
        if not len(rows):
            return
        rows = with_labels(rows.reindex(columns=COLUMNS))
        for key, frame in rows.groupby(rows["sequence_key"].astype(str), sort=True):
            if not key:
                digest = hashlib.sha256(frame.to_csv().encode()).hexdigest()[:12]
                key = f"adopted-{digest}"
            atomic_write(frame.reset_index(drop=True), self.partitions / f"{key}.parquet",
                         "parquet")

    def sequence(self, key: str) -> SequenceWriter:
        return SequenceWriter(self.partitions / f"{key}.parquet")

    def append(self, row: ResultRow) -> None:
        """Store one finished row in its sequence's partition, the record; the tables are
        consolidated when the sequence ends (``finish``): consolidating after every row would
        re-read every partition each time, quadratic in the run."""
        key = row.sequence_key or "unkeyed"
        if key not in self.writers:
            self.writers[key] = self.sequence(key)
        self.writers[key].append(row)

    def finish(self, key: str, end: str) -> None:
        """Record why the sequence ``key`` ended, in its partition (a worker's partition
        records it itself); once one has finished, what an ``--overwrite`` set aside goes."""
        if key in self.writers:
            self.writers[key].finish(end)
        if end in FINISHED:
            self.keep_new()
        # the tables are derived from the partitions (which readers merge anyway): refreshed
        # every CONSOLIDATE_SECONDS while a run lasts, and by its end, since each refresh
        # reads every partition (quadratic in the run if done after each sequence)
        if time.monotonic() - self.consolidated_at >= CONSOLIDATE_SECONDS:
            self.consolidate()

    def table(self) -> pd.DataFrame:
        """All rows in the folder's partitions: earlier runs' and this run's (what the folder
        held beside them was written back when it was opened)."""
        return table_of(list(read_partitions(self.out)[0].values()))

    def consolidate(self, locked: bool = False) -> pd.DataFrame:
        """results.parquet and results.csv from every partition (under the folder's lock)."""
        if not locked:
            with folder_lock(self.out):
                return self.consolidate(locked=True)
        # partitions' checksums first: one that a worker replaces meanwhile then fails them,
        # and the tables are read from the partitions until the next consolidation
        self.consolidated_at = time.monotonic()
        before = checksums(self.out, tables=False)
        table = self.table()
        atomic_write(table, self.parquet, "parquet")
        atomic_write(table, self.csv, "csv")
        written = {**before, **{path.name: hashlib.sha256(path.read_bytes()).hexdigest()
                                for path in (self.parquet, self.csv)}}
        atomic_text(json.dumps(written, indent=1), self.out / MANIFEST)
        return table

    def finished_keys(self) -> set[str]:
        """Keys of the sequences in this folder that ended (not cut short): a rerun with the
        same spec reuses them."""
        table = self.table()
        done = table[table["sequence_end"].isin(FINISHED)]
        return set(done["sequence_key"]) - {""}


"""What a results folder holds, read without writing a byte (docs/reliability.md, "The store").

The record is the partitions, ``sequences/<sequence key>.parquet``, one per sequence. The
tables ``results.parquet`` and ``results.csv`` are derived from them. A sequence whose partition
is missing or unreadable while the tables hold its rows is kept from the tables, counted in a
note, never dropped; a folder that an ``--overwrite`` run set aside (``.previous-*``) and did
not replace, because that run ended before it finished a sequence, still counts: its sequences
are read where the folder has no finished one of the same key. ``FolderState`` is the one
reading that ``read_results`` (the readers) and ``ResultStore`` (the writer, which repairs what
it reads) share."""

from __future__ import annotations

import fcntl
import json
import os
from contextlib import contextmanager, nullcontext
from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

from bench.matrix.files import checksums, read_snapshot, read_table
from bench.sequence.rows import COLUMNS, FINISHED, with_labels

MANIFEST = "results.sha256"  # checksums of the partitions and tables at consolidation
PREVIOUS = ".previous-"  # prefix of a folder holding results an --overwrite run set aside
OWNER = ".owner"  # the lock file its run holds while it runs


def finished(frame: pd.DataFrame | None) -> bool:
    """Whether a partition's sequence ended (not cut short)."""
    return frame is not None and len(frame) > 0 and "sequence_end" in frame and bool(
        frame["sequence_end"].isin(FINISHED).all())


def read_partitions(folder: Path) -> tuple[dict[str, pd.DataFrame], list[Path]]:
    """The readable partitions of ``folder/sequences`` by file stem, and the unreadable ones."""
    frames, damaged = {}, []
    for path in sorted((folder / "sequences").glob("*.parquet")):
        try:
            frames[path.stem] = read_snapshot(path)
        except Exception:  # pyarrow raises several types for a damaged file
            damaged.append(path)
    return frames, damaged


def owner_alive(previous: Path) -> bool:
    """Whether the run that set ``previous`` aside still runs: it holds a lock on its owner
    file, which the system releases when the process ends in any way (SIGKILL included)."""
    try:
        handle = os.open(previous / OWNER, os.O_RDONLY)
    except OSError:
        return False  # no owner file: an older version's, or the run died creating it
    try:
        fcntl.flock(handle, fcntl.LOCK_SH | fcntl.LOCK_NB)
        return False
    except OSError:
        return True
    finally:
        os.close(handle)


@contextmanager
def shared_lock(folder: Path):
    """A shared lock on ``folder/.lock`` when the file exists (a reader creates nothing)."""
    try:
        handle = os.open(folder / ".lock", os.O_RDONLY)
    except OSError:
        yield
        return
    try:
        fcntl.flock(handle, fcntl.LOCK_SH)
        yield
    finally:
        os.close(handle)


def keys_of(frames) -> set[str]:
    return {str(k) for f in frames for k in f.get("sequence_key", pd.Series(dtype=str))}


def table_of(frames: list[pd.DataFrame]) -> pd.DataFrame:
    """One table of ``frames``, every column, in the order the runs wrote them."""
    frames = [f for f in frames if len(f)]
    if not frames:
        return pd.DataFrame(columns=COLUMNS)
    table = with_labels(pd.concat(frames, ignore_index=True).reindex(columns=COLUMNS))
    return table.sort_values(["run_id"], kind="stable").reset_index(drop=True)


@dataclass(frozen=True)
class SetAside:
    """One ``.previous-*`` folder: its partitions and tables, and whether its run still runs."""

    path: Path
    partitions: dict[str, pd.DataFrame]
    table: pd.DataFrame | None
    alive: bool


@dataclass(frozen=True)
class FolderState:
    """The rows of a results folder and where each came from, for readers and the writer."""

    folder: Path
    partitions: dict[str, pd.DataFrame]  # by file stem: the folder's own
    damaged: list[Path]  # partitions that cannot be read
    table: pd.DataFrame | None  # the consolidated table (parquet, else CSV), if readable
    set_aside: list[SetAside] = field(default_factory=list)

    @classmethod
    def read(cls, folder: str | Path, shared: bool = False) -> FolderState:
        """The folder as it is; ``shared``: under a shared lock of its lock file (if it has
        one), so that no writer sets results aside or puts them back meanwhile (a writer,
        which holds the exclusive lock, reads without it)."""
        folder = Path(folder)
        with shared_lock(folder) if shared else nullcontext():
            partitions, damaged = read_partitions(folder)
            set_aside = [SetAside(p, read_partitions(p)[0], read_table(p), owner_alive(p))
                         for p in sorted(folder.glob(f"{PREVIOUS}*")) if p.is_dir()]
            return cls(folder, partitions, damaged, read_table(folder), set_aside)

    def merged(self) -> dict[str, pd.DataFrame]:
        """The partitions with those set aside: a set-aside sequence is taken where the folder
        has none of its stem, or only one cut short while the set-aside one finished."""
        merged = dict(self.partitions)
        for aside in self.set_aside:
            for stem, frame in aside.partitions.items():
                if stem not in merged or (finished(frame) and not finished(merged[stem])):
                    merged[stem] = frame
        return merged

    def restored(self) -> list[tuple[str, pd.DataFrame]]:
        """(stem, rows) of the set-aside sequences that ``merged`` takes."""
        own = self.partitions
        return [(stem, frame) for stem, frame in self.merged().items()
                if stem not in own or frame is not own[stem]]

    def orphans(self) -> pd.DataFrame:
        """Rows of the tables (the folder's and those set aside) whose sequence has no
        readable partition: the record lost them, the tables still hold them."""
        kept = keys_of(self.merged().values())
        tables = [t for t in (self.table, *(a.table for a in self.set_aside)) if t is not None]
        frames = [t[~t["sequence_key"].astype(str).isin(kept)]
                  if "sequence_key" in t.columns else t for t in tables]
        frames = [f for f in frames if len(f)]
        if not frames:
            return pd.DataFrame(columns=COLUMNS)
        orphans = pd.concat(frames, ignore_index=True)
        if "sequence_key" not in orphans.columns:  # an older version's table
            orphans["sequence_key"] = ""
        same = [c for c in ("sequence_key", "level", "run_id") if c in orphans.columns]
        return orphans.drop_duplicates(subset=same) if same else orphans

    def rows(self) -> pd.DataFrame:
        """Every row the folder holds: the merged partitions, then the orphans (what a reader
        sees)."""
        return table_of([*self.merged().values(), self.orphans()])

    def record(self) -> pd.DataFrame:
        """The rows of the folder's own partitions, the record (``ResultStore.table`` reads
        just these)."""
        return table_of(list(self.partitions.values()))

    def tables_current(self) -> bool:
        """Whether the tables on disk are what the partitions give: the checksums recorded at
        their consolidation match every partition and both tables, and nothing is set aside."""
        if self.set_aside or self.damaged:
            return False
        try:
            return json.loads((self.folder / MANIFEST).read_text()) == checksums(self.folder)
        except (OSError, ValueError):
            return False

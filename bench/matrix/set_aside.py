"""``--overwrite`` as a transaction (docs/reliability.md, "The store"): the earlier results are
moved into ``.previous-<pid>-<ns>/``, whose owner file the run keeps locked while it runs; once a
sequence of the new run has finished they are discarded (renamed ``.discard-*``, then deleted),
and if the run ends before that, by an error or a signal, they come back. A run killed outright
(SIGKILL, power loss) leaves the folder with an owner file nobody holds: readers count its rows
(``folder_state``) and the next run puts them back (``restore_into``)."""

from __future__ import annotations

import fcntl
import os
import shutil
import time
from contextlib import suppress
from dataclasses import dataclass
from pathlib import Path

from bench.matrix.folder_state import MANIFEST, OWNER, PREVIOUS, FolderState

MOVED = ("results.parquet", "results.csv", MANIFEST, "rates.csv", "rates.md", "sequences")
DISCARD = ".discard-"  # a set-aside folder being deleted: never read, deleted by the next run


@dataclass
class SetAsideFolder:
    """The folder an ``--overwrite`` run moved the earlier results into, and its held lock."""

    path: Path
    handle: int  # the owner file, locked while the run runs

    @classmethod
    def create(cls, out: Path) -> SetAsideFolder | None:
        """Move the results of ``out`` aside (None when it has none): the owner file is
        created and locked first, so that no moment exists in which a reader could take the
        folder for one whose run has ended."""
        present = [name for name in MOVED if (out / name).exists()]
        if not present:
            return None
        path = out / f"{PREVIOUS}{os.getpid()}-{time.time_ns()}"
        path.mkdir()
        handle = os.open(path / OWNER, os.O_RDWR | os.O_CREAT, 0o644)
        fcntl.flock(handle, fcntl.LOCK_EX)
        os.write(handle, str(os.getpid()).encode())
        for name in present:
            os.replace(out / name, path / name)
        return cls(path, handle)

    def discard(self) -> None:
        """Delete what is left in the folder (all of it once the new results stand, what was
        not moved back otherwise) and let go of its lock."""
        discard_folder(self.path)
        with suppress(OSError):
            os.close(self.handle)


def discard_folder(path: Path) -> None:
    """Delete ``path``, renamed first so that a half-deleted folder is never read."""
    target = path.with_name(DISCARD + path.name.removeprefix(PREVIOUS))
    with suppress(FileNotFoundError):
        os.replace(path, target)
    shutil.rmtree(target, ignore_errors=True)


def discard(out: Path) -> None:
    """Delete what an ended run was deleting (``.discard-*``)."""
    for path in out.glob(f"{DISCARD}*"):
        shutil.rmtree(path, ignore_errors=True)


def restore_into(out: Path, aside: Path, state: FolderState) -> None:
    """Move back from ``aside`` every partition that ``state.merged`` takes from it (one the
    folder lacks, or finished where the folder's was cut short), the damaged ones the folder
    lacks and the rates. The caller writes back the rows that only its tables hold
    (``state.orphans``) and then discards it."""
    mine = next((a for a in state.set_aside if a.path == aside), None)
    if mine is None:
        return
    merged = state.merged()
    (out / "sequences").mkdir(exist_ok=True)
    for stem, frame in mine.partitions.items():
        if merged.get(stem) is frame:
            os.replace(aside / "sequences" / f"{stem}.parquet", out / "sequences" /
                       f"{stem}.parquet")
    for path in sorted(aside.glob("sequences/*.damaged")):
        if not (out / "sequences" / path.name).exists():
            os.replace(path, out / "sequences" / path.name)
    for name in ("rates.csv", "rates.md"):
        if (aside / name).exists() and not (out / name).exists():
            os.replace(aside / name, out / name)

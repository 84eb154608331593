"""Files of a results folder: a parquet read from one open, writes that either happen whole or
not at all (a temporary file, fsync, rename, fsync of the folder), a full disk named in one
line with nothing half-written left, and the checksums that say whether the tables are stale
(docs/reliability.md, "The store")."""

from __future__ import annotations

import errno
import hashlib
import io
import os
import re
import shutil
import socket
import time
from contextlib import contextmanager, suppress
from pathlib import Path

import pandas as pd

FULL = (errno.ENOSPC, errno.EDQUOT, errno.EFBIG)  # the write did not fit
HOST = re.sub(r"[^A-Za-z0-9-]", "-", socket.gethostname().split(".")[0]) or "host"
TEMPORARY = re.compile(r"\.(?P<host>[A-Za-z0-9-]+)~(?P<pid>\d+)\.tmp$")
ABANDONED_AFTER = 86400.0  # seconds: a temporary file of another machine's process this old


class DiskFull(OSError):
    """A write that did not fit on its file system: names the folder and the space it needed."""

    def __init__(self, path: Path, needed: int, error: OSError):
        folder = Path(path).parent
        try:
            free = shutil.disk_usage(folder).free
        except OSError:
            free = 0
        super().__init__(error.errno, f"no space left on the device of {folder} while writing "
                         f"{Path(path).name} (at least {_size(needed)} needed, {_size(free)} "
                         "free); free some space and run again: every row finished before "
                         "this is kept")

    def __str__(self) -> str:
        return self.strerror


def _size(nbytes: int) -> str:
    for unit, scale in (("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if nbytes >= scale:
            return f"{nbytes / scale:.1f} {unit}"
    return f"{nbytes} bytes"


def _alive(pid: int) -> bool:
    """Whether process ``pid`` runs on this machine (a zombie, ended but not yet reaped by its
    parent, does not)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # another user's process
        return True
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except (OSError, IndexError):  # no /proc (not Linux): the signal's answer stands
        return True
    return state not in ("Z", "X")


def abandoned_temporaries(folder: Path) -> list[Path]:
    """Temporary files under ``folder`` whose writer ended before renaming them (a killed
    process): of this machine, when their process no longer runs; of another (a Dask worker on
    shared storage), when a day old."""
    found = []
    for path in folder.rglob(".*.tmp"):
        match = TEMPORARY.search(path.name)
        if match is None:
            continue
        if match["host"] == HOST:
            if not _alive(int(match["pid"])):
                found.append(path)
        elif time.time() - path.stat().st_mtime > ABANDONED_AFTER:
            found.append(path)
    return found


def read_snapshot(path: Path) -> pd.DataFrame:
    """A parquet file read from one open: pyarrow opens a path again for its pages after the
    footer, so a file replaced in between by another writer would be read half old, half new."""
    return pd.read_parquet(io.BytesIO(path.read_bytes()))


def _fsync_folder(folder: Path) -> None:
    with suppress(OSError):  # some file systems cannot sync a folder; the rename still holds
        handle = os.open(folder, os.O_RDONLY)
        try:
            os.fsync(handle)
        finally:
            os.close(handle)


@contextmanager
def atomic_path(path: Path, needed: int = 0):
    """A temporary path of this process beside ``path``: what is written to it becomes
    ``path`` (synced, then renamed) when the block ends, or nothing at all if it raises; a full
    disk raises DiskFull naming the folder and ``needed`` (or the bytes written so far)."""
    path = Path(path)
    tmp = path.with_name(f".{path.name}.{HOST}~{os.getpid()}.tmp")
    try:
        yield tmp
        with open(tmp, "rb+") as handle:
            os.fsync(handle.fileno())
        os.replace(tmp, path)
    except OSError as error:
        written = tmp.stat().st_size if tmp.exists() else 0
        with suppress(OSError):
            tmp.unlink()
        if error.errno in FULL and not isinstance(error, DiskFull):
            raise DiskFull(path, max(needed, written), error) from None
        raise
    except BaseException:
        with suppress(OSError):
            tmp.unlink()
        raise
    _fsync_folder(path.parent)


def atomic_bytes(data: bytes, path: Path) -> None:
    """Write ``data`` to ``path`` whole or not at all (``atomic_path``)."""
    with atomic_path(path, len(data)) as tmp:
        with open(tmp, "wb") as handle:
            handle.write(data)


def atomic_text(text: str, path: Path) -> None:
    atomic_bytes(text.encode(), path)


def frame_bytes(frame: pd.DataFrame, kind: str) -> bytes:
    """``frame`` as parquet or csv, in memory (so its size is known before it is written)."""
    if kind == "parquet":
        buffer = io.BytesIO()
        frame.to_parquet(buffer, index=False)
        return buffer.getvalue()
    return frame.to_csv(index=False).encode()


def atomic_write(frame: pd.DataFrame, path: Path, kind: str) -> None:
    """Write ``frame`` to ``path`` as parquet or csv, whole or not at all."""
    atomic_bytes(frame_bytes(frame, kind), path)


def checksums(folder: Path, tables: bool = True) -> dict[str, str]:
    """SHA-256 of every partition and (``tables``) of both tables of ``folder`` ('' for a
    missing file)."""
    paths = sorted((folder / "sequences").glob("*.parquet"))
    if tables:
        paths += [folder / "results.parquet", folder / "results.csv"]
    return {str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
            if p.exists() else "" for p in paths}


def read_table(folder: Path) -> pd.DataFrame | None:
    """The rows of ``folder``'s consolidated table: results.parquet, else its CSV mirror when
    that is intact; None when neither can be read."""
    for path, read in ((folder / "results.parquet", read_snapshot),
                       (folder / "results.csv", pd.read_csv)):
        try:
            table = read(path)
        except Exception:  # missing or damaged (pyarrow, pandas raise several types)
            continue
        if "scene" in table.columns and "level" in table.columns:
            return table
    return None

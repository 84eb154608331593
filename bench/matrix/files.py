"""Files of a results folder that may be damaged: a parquet read from one open, atomic writes,
the checksums that say whether the tables are stale, and a damaged partition restored from
the tables or set aside (docs/reliability.md)."""

from __future__ import annotations

import hashlib
import io
import os
import sys
from pathlib import Path

import pandas as pd

from bench.sequence.rows import COLUMNS, with_labels


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


def checksums(folder: Path, tables: bool = True) -> dict[str, str]:
    """SHA-256 of every partition and (``tables``) of both tables of ``folder`` ('' for a
    missing file)."""
    paths = sorted((folder / "sequences").glob("*.parquet"))
    if tables:
        paths += [folder / "results.parquet", folder / "results.csv"]
    return {str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
            if p.exists() else "" for p in paths}


def read_partition(path: Path) -> pd.DataFrame | None:
    """The rows of one partition. A damaged one is rewritten from the rows of its sequence in
    the folder's tables when they hold them, else renamed ``*.damaged`` (its sequence is then
    rerun by the next run); either way one line on standard error says so."""
    try:
        return read_snapshot(path)
    except Exception as error:  # pyarrow raises several types for a damaged file
        why = f"{path} is unreadable ({type(error).__name__}: {error})"
    rows = _table_rows(path.parent.parent, path.stem)
    if rows is not None and len(rows):
        atomic_write(with_labels(rows.reindex(columns=COLUMNS)), path, "parquet")
        print(f"note: {why}; restored its {len(rows)} rows from the folder's results table",
              file=sys.stderr)
        return read_snapshot(path)
    damaged = path.with_name(path.name + ".damaged")
    os.replace(path, damaged)
    print(f"warning: {why}, and the folder's tables do not hold its rows; set aside as "
          f"{damaged.name}: the next run reruns its sequence (delete the file when done)",
          file=sys.stderr)
    return None


def _table_rows(folder: Path, key: str) -> pd.DataFrame | None:
    """The rows of sequence ``key`` in ``folder``'s parquet table, else its CSV mirror."""
    for path, read in ((folder / "results.parquet", read_snapshot),
                       (folder / "results.csv", pd.read_csv)):
        try:
            table = read(path)
            return table[table["sequence_key"].astype(str) == key]
        except Exception:  # missing or damaged too: try the next, else nothing to restore
            continue
    return None

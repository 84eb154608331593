"""The history of the suite's figures (docs/history.md): one row per (commit, figure) in a CSV
file kept in the repository, ``history/figures.csv``."""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, fields
from pathlib import Path

import pandas as pd

from bench.matrix.files import atomic_text

HISTORY_FILE = Path("history") / "figures.csv"
KINDS = ("time", "memory", "ratio", "rate", "effectivity", "error", "count")


@dataclass(frozen=True)
class Figure:
    """One figure of one commit: ``source`` (a registered source: verify, compare, scaling),
    ``name`` (unique within the source), ``value``, its measured ``noise`` (absolute; NaN where
    the source measures none), its ``kind`` (KINDS: how much it may move by chance)."""

    commit: str
    recorded: str
    source: str
    name: str
    value: float
    kind: str
    noise: float = math.nan

    def __post_init__(self):
        if self.kind not in KINDS:
            raise ValueError(f"kind={self.kind!r} is not one of {', '.join(KINDS)}")


COLUMNS = [f.name for f in fields(Figure)]


def read_history(path: str | Path = HISTORY_FILE) -> pd.DataFrame:
    """Every recorded figure (an empty table with the columns if there is no file)."""
    path = Path(path)
    if not path.exists():
        return pd.DataFrame(columns=COLUMNS)
    frame = pd.read_csv(path, dtype={"commit": str, "recorded": str, "source": str,
                                     "name": str, "kind": str})
    missing = [c for c in COLUMNS if c not in frame]
    if missing:
        raise ValueError(f"history file {str(path)!r} lacks the columns {', '.join(missing)}")
    return frame[COLUMNS]


def append_figures(figures: list[Figure], path: str | Path = HISTORY_FILE) -> pd.DataFrame:
    """The history with ``figures`` added (an entry of the same commit, source and name is
    replaced: recording again corrects, never duplicates), written back atomically."""
    path = Path(path)
    new = pd.DataFrame([asdict(f) for f in figures], columns=COLUMNS)
    old = read_history(path)
    keys = ["commit", "source", "name"]
    if len(old) and len(new):
        stale = old.set_index(keys).index.isin(new.set_index(keys).index)
        old = old[~stale]
    frame = pd.concat([old, new], ignore_index=True) if len(old) else new
    path.parent.mkdir(parents=True, exist_ok=True)
    atomic_text(frame.to_csv(index=False), path)
    return frame


def commit_order(frame: pd.DataFrame) -> list[str]:
    """The commits in the order they were first recorded."""
    return list(dict.fromkeys(frame.sort_values("recorded", kind="stable")["commit"]))

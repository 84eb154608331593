"""Which figures moved beyond their noise since the last entry (docs/history.md).

A figure's noise band is the largest of: three times its measured noise (the compare's gap
between a combination's best and second-best samples), twice the spread of its earlier values
(their standard deviation over the last HISTORY_WINDOW entries, from three on), and a floor
per kind (FLOORS, relative to the last value): a timing may move 10 % by chance on a shared
2-core machine, a memory peak 5 %, a deterministic figure (a rate, an effectivity, a ratio of
errors) 2 % (a change of code legitimately moves it less; a 20 % looser bound is caught).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd

from bench.history.store import commit_order

FLOORS = {"time": 0.10, "memory": 0.05, "ratio": 0.10, "rate": 0.02, "effectivity": 0.02,
          "error": 0.02, "count": 0.02}
HISTORY_WINDOW = 10


@dataclass(frozen=True)
class Move:
    """A figure of the last commit against its previous entry: ``moved`` when the change
    exceeds ``band``."""

    source: str
    name: str
    kind: str
    previous: float
    value: float
    band: float

    @property
    def change(self) -> float:
        return self.value - self.previous

    @property
    def relative(self) -> float:
        return self.change / abs(self.previous) if self.previous else math.inf

    @property
    def moved(self) -> bool:
        return abs(self.change) > self.band

    def line(self) -> str:
        return (f"{self.source}: {self.name}: {self.previous:.4g} -> {self.value:.4g} "
                f"({self.relative:+.1%}, band {self.band:.3g})")


def noise_band(kind: str, earlier: pd.DataFrame, latest: pd.Series) -> float:
    """The band a change of ``latest`` against the last of ``earlier`` must exceed."""
    previous = earlier.iloc[-1]
    measured = np.nanmax([3 * latest["noise"], 3 * previous["noise"], 0.0])
    values = earlier["value"].to_numpy(dtype=float)[-HISTORY_WINDOW:]
    spread = 2 * float(np.std(values, ddof=1)) if values.size >= 3 else 0.0
    return float(max(measured, spread, FLOORS[kind] * abs(previous["value"])))


def moves(history: pd.DataFrame, commit: str | None = None) -> list[Move]:
    """Every figure of ``commit`` (default: the last recorded) that has an earlier entry,
    against that entry."""
    order = commit_order(history)
    if not order:
        return []
    commit = order[-1] if commit is None else commit
    before = order[:order.index(commit)] if commit in order else order
    out = []
    for (source, name), group in history.groupby(["source", "name"], sort=True):
        latest = group[group["commit"] == commit]
        earlier = group[group["commit"].isin(before)].copy()
        if latest.empty or earlier.empty:
            continue
        earlier["position"] = earlier["commit"].map(before.index)
        earlier = earlier.sort_values("position")
        row = latest.iloc[-1]
        out.append(Move(source, name, row["kind"], float(earlier.iloc[-1]["value"]),
                        float(row["value"]), noise_band(row["kind"], earlier, row)))
    return out

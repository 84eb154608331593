"""What a run prints as it goes: one line per level (``progress``), a table per sequence at
the end (``summary``), and a live progress line for the whole matrix on standard error
(sequences done, running and left, the most DOFs reached, elapsed and estimated remaining
time; quiet when standard error is not a terminal)."""

from __future__ import annotations

import sys
import time

import pandas as pd

from bench.sequence.loop import LevelResult
from bench.sequence.rows import KEYS, level_time


class Progress:
    def __init__(self, total: int, stream=None):
        self.stream = sys.stderr if stream is None else stream
        self.live = self.stream.isatty()
        self.total, self.done, self.dofs = total, 0, 0
        self.start = time.perf_counter()

    def level(self, then):
        """A per-level callback that also updates the line (``then``: the per-level printer)."""
        def on_level(result) -> None:
            then(result)
            self.dofs = max(self.dofs, int(result.row.ndofs))
            self.show()
        return on_level

    def sequence(self, spec, end: str) -> None:
        self.done += 1
        self.show()

    def show(self) -> None:
        if not self.live:
            return
        elapsed = time.perf_counter() - self.start
        left = self.total - self.done
        eta = f"{elapsed / self.done * left:6.0f} s" if self.done else "     ?"
        self.stream.write(f"\r[matrix] {self.done}/{self.total} sequences done, {left} left, "
                          f"max {self.dofs} DOFs, {elapsed:6.0f} s elapsed, ~{eta} to go ")
        self.stream.flush()

    def close(self) -> None:
        if self.live:
            self.stream.write("\n")
            self.stream.flush()


SUMMARY_COLUMNS = ["level", "ndofs", "energy", "contact_force", "active_constraints", "eta",
                   "eta_0", "eta_geometric", "eta_complementarity", "energy_error",
                   "effectivity_index", "iterations", "t_solve", "status"]


def progress(result: LevelResult) -> None:
    r = result.row
    print(f"{r.scene}/{r.formulation}/{r.solver}/{r.estimator}/{r.strategy} "
          f"level {r.level:2d}  ndofs {r.ndofs:8d}  eta {r.eta:11.5e}  "
          f"time {level_time(r):7.2f} s  "
          f"{r.status}{' (' + r.reason + ')' if r.reason else ''}", flush=True)


def summary(table: pd.DataFrame) -> str:
    parts = []
    for key, group in table.groupby(KEYS, sort=False, dropna=False):
        parts.append("== " + " / ".join(str(k) for k in key if str(k)))
        parts.append(group[SUMMARY_COLUMNS].to_string(index=False, float_format="{:.6g}".format))
    return "\n".join(parts)

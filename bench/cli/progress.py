"""What a run prints as it goes (docs/command-line.md, "What a run prints"): on a terminal a
progress bar on standard error (sequences done of all, the current scene, elapsed and estimated
remaining time); elsewhere at most PROGRESS_LINES lines for the whole matrix; with ``quiet``
nothing. ``run`` also prints one line per level (``progress``) and a table per sequence at
the end (``summary``)."""

from __future__ import annotations

import sys
import time

import pandas as pd
from tqdm import tqdm

from bench.report.console import duration
from bench.sequence.loop import LevelResult
from bench.sequence.rows import KEYS, level_time

PROGRESS_LINES = 10  # lines a whole matrix prints when standard error is not a terminal


class Progress:
    """Sequences done of ``total``: a bar on a terminal, elsewhere a line each time another
    1/``lines`` of them is done."""

    def __init__(self, total: int, stream=None, quiet: bool = False, what: str = "sequences",
                 lines: int = PROGRESS_LINES):
        self.stream = sys.stderr if stream is None else stream
        self.quiet, self.what, self.lines = quiet, what, lines
        self.total, self.done, self.shown = total, 0, 0
        self.start = time.perf_counter()
        self.bar = None
        if not quiet and self.stream.isatty():
            self.bar = tqdm(total=total, file=self.stream, unit=" seq", dynamic_ncols=True,
                            desc=what, bar_format="{desc}: {n_fmt}/{total_fmt} |{bar}| "
                            "{elapsed} elapsed, ~{remaining} left{postfix}")

    def level(self, then):
        """A per-level callback that prints through the bar (``then``: the printer)."""
        def on_level(result: LevelResult) -> None:
            if self.bar is not None:
                self.bar.set_postfix_str(str(result.row.scene), refresh=False)
            if not self.quiet:
                then(result)
        return on_level

    def sequence(self, spec, end: str = "") -> None:
        self.done += 1
        if self.bar is not None:
            self.bar.set_postfix_str(str(spec.scene), refresh=False)
            self.bar.update(1)
        elif not self.quiet and self.total and (
                self.done * self.lines // self.total > self.shown or self.done == self.total):
            self.shown = self.done * self.lines // self.total
            elapsed = time.perf_counter() - self.start
            left = elapsed / self.done * (self.total - self.done)
            print(f"[{self.what}] {self.done} of {self.total} done, {duration(elapsed)} "
                  f"elapsed, ~{duration(left)} left", file=self.stream, flush=True)

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()
            self.bar = None


SUMMARY_COLUMNS = ["level", "ndofs", "energy", "contact_force", "active_constraints", "eta",
                   "eta_0", "eta_geometric", "eta_complementarity", "energy_error",
                   "effectivity_index", "iterations", "t_solve", "status"]


def progress(result: LevelResult) -> None:
    r = result.row
    tqdm.write(f"{r.scene}/{r.formulation}/{r.solver}/{r.estimator}/{r.strategy} "
               f"level {r.level:2d}  ndofs {r.ndofs:8d}  eta {r.eta:11.5e}  "
               f"time {level_time(r):7.2f} s  "
               f"{r.status}{' (' + r.reason + ')' if r.reason else ''}", file=sys.stdout)
    sys.stdout.flush()


def summary(table: pd.DataFrame) -> str:
    parts = []
    for key, group in table.groupby(KEYS, sort=False, dropna=False):
        parts.append("== " + " / ".join(str(k) for k in key if str(k)))
        parts.append(group[SUMMARY_COLUMNS].to_string(index=False, float_format="{:.6g}".format))
    return "\n".join(parts)

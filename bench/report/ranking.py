"""The cheapest combinations to a relative error (docs/report.md, "Cost and ties"): each
sequence's time to the first level at or below the target, the best of its repeated samples
(``bench.matrix.cost``) where it was timed again, and the combinations whose best lies within
the cheapest's two best samples counted as tied with it. Combinations timed once (not
candidates, or a run without repeats) rank after the timed ones and never tie."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from bench.matrix.cost import measured, reaches


def sig3(value: float) -> str:
    """Three significant figures, never an exponent in prose: 2120, 0.000341, 4.4."""
    return np.format_float_positional(float(value), precision=3, unique=False,
                                      fractional=False, trim="-")


def combination(row, estimator: bool = True) -> str:
    """'vi/active-set/residual/adaptive P1' (the cell named unless triangles)."""
    parts = [row["formulation"], row["solver"], *([row["estimator"]] if estimator else []),
             row["strategy"]]
    cell = str(row.get("cell", "tri"))
    return "/".join(map(str, parts)) + f" P{int(row['order'])}" + (
        "" if cell in ("tri", "nan") else f" {cell}")


@dataclass(frozen=True)
class Ranked:
    """One combination's cost to a target: the best of its samples (``seconds`` = ``low``)
    and the second best (``high``; the best again for a single sample)."""

    combination: str
    ndofs: int
    seconds: float
    low: float
    high: float
    samples: int

    def text(self) -> str:
        timed = f", best of {self.samples}" if self.samples > 1 else ", timed once"
        return f"{self.combination} {sig3(self.seconds)} s ({self.ndofs} DOFs{timed})"


@dataclass(frozen=True)
class Ranking:
    """The combinations that reach ``target``, cheapest first, and how many tie with it."""

    target: float
    ranked: tuple[Ranked, ...]
    ties: int
    compared: int
    smallest: tuple[float, str, int] | None  # (relative error, combination, DOFs)

    def frame(self, top: int = 5) -> pd.DataFrame:
        return pd.DataFrame([{"combination": r.combination, "DOFs": r.ndofs,
                              "best [s]": sig3(r.seconds), "second best [s]": sig3(r.high),
                              "samples": r.samples} for r in self.ranked[:top]])


def samples_of(timings: pd.DataFrame | None, key: str, level: int, first: float) -> np.ndarray:
    """The cumulative seconds to ``level`` of sequence ``key``, sorted: every sample timed
    again, else the matrix's single one (``first``)."""
    if timings is None or timings.empty:
        return np.array([first])
    mine = timings[(timings["sequence_key"] == key) & (timings["level"] == level)]
    return np.sort(mine["seconds"].to_numpy()) if len(mine) else np.array([first])


def rank(group: pd.DataFrame, norm: float, target: float,
         timings: pd.DataFrame | None) -> Ranking:
    """The sequences of one scene that reach ``target``: the timed again first, by their
    best sample, then the others by their single time."""
    rows = {str(k): r for k, r in group.groupby("sequence_key")}
    ranked = []
    for reach in reaches(group, norm, target):
        seconds = samples_of(timings, reach.sequence_key, reach.level, reach.seconds)
        first = rows[reach.sequence_key].iloc[0]
        ranked.append(Ranked(combination(first), reach.ndofs,
                             float(seconds[0]), float(seconds[0]),
                             float(seconds[min(1, seconds.size - 1)]), int(seconds.size)))
    timed = timings is not None and not timings.empty
    ranked.sort(key=lambda r: (timed and r.samples == 1, r.seconds))
    ties = sum(r.samples > 1 and r.low <= ranked[0].high
               for r in ranked[1:]) if ranked and ranked[0].samples > 1 else 0
    usable = measured(group)
    smallest = None
    if len(usable):
        best = usable.loc[usable["energy_error"].idxmin()]
        smallest = (float(best["energy_error"] / norm), combination(best), int(best["ndofs"]))
    return Ranking(target, tuple(ranked), ties, usable.groupby("sequence_key").ngroups, smallest)


def ranking_text(ranking: Ranking, shown: int = 2) -> str:
    """'vi/... P3 0.17 s [0.16..0.18] (1302 DOFs), tied with ...; 30 of 44 reach it'."""
    if not ranking.ranked and ranking.smallest is not None:
        error, name, ndofs = ranking.smallest
        return (f"none of {ranking.compared} reached it; smallest {sig3(error)} ({name}, "
                f"{ndofs} DOFs)")
    if not ranking.ranked:
        return "no error measured against a sharp enough truth"
    text = ranking.ranked[0].text()
    if ranking.ties:
        tied = ", ".join(r.text() for r in ranking.ranked[1:1 + min(ranking.ties, shown)])
        more = ranking.ties - min(ranking.ties, shown)
        text += f", tied with {tied}" + (f" and {more} more" if more else "")
    return text + f"; {len(ranking.ranked)} of {ranking.compared} reach it"


def spread_text(timings: pd.DataFrame | None) -> str:
    """The measured run-to-run spread of the samples over the timed candidates: of the best
    against the second best, and of all of them, each relative to the best."""
    if timings is None or timings.empty:
        return ("each time was measured once (no repeats): a difference below the machine's "
                "timing noise is not a ranking, and nothing is shown as tied")
    last = timings.sort_values("level").groupby(["sequence_key", "sample"]).tail(1)
    ordered = last.groupby("sequence_key")["seconds"].agg(lambda s: np.sort(s.to_numpy()))
    second = ordered.map(lambda s: (s[min(1, s.size - 1)] - s[0]) / s[0])
    whole = ordered.map(lambda s: (s[-1] - s[0]) / s[0])
    return (f"each candidate to be the cheapest was timed {int(ordered.map(len).max())} more "
            f"times in one fresh single-threaded process, its cost the best; over "
            f"{len(ordered)} candidates the second best is {100 * float(second.median()):.1f} "
            f"% above the best in the median ({100 * float(second.max()):.0f} % at most) and the "
            f"slowest {100 * float(whole.median()):.0f} % ({100 * float(whole.max()):.0f} % at "
            "most); two tie when the best of one is within the other's two best")

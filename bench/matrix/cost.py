"""The cost that ranks (docs/report.md, "Cost and ties"): the cumulative wall time of a
sequence's timed phases up to the first level whose relative energy error reaches a target,
timed again for the candidates to be the cheapest so that each has several samples.

A single sub-second timing is noisier than the differences between the combinations it ranks,
so after the matrix the sequences whose first time to a target is within CANDIDATE_FACTOR of
the fastest (at most MAX_CANDIDATES of them) are run ``repeats`` more times (twice if one
takes LONG_SAMPLE seconds or more), one after the other in one fresh single-threaded process
(the matrix may have run them beside other workers), without errors or cross-checks (only what
a user's run does: assemble, solve, estimate, refine), up to that level. Their cost is the
best of these samples (interference only ever adds time), and two combinations tie when the
best of one is within the other's two best (``bench.report.ranking``); the samples' spread is
the measured run-to-run noise that the report states."""

from __future__ import annotations

import json
import multiprocessing
import os
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor
from contextlib import contextmanager
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
import pandas as pd

from bench.matrix.distributed import SINGLE_THREAD
from bench.matrix.files import atomic_write
from bench.matrix.plugins import load_plugins
from bench.matrix.scene_files import load_scene_files
from bench.matrix.spec import SequenceSpec, build_scene
from bench.matrix.task import warm_up
from bench.sequence.loop import run_sequence
from bench.sequence.rows import KEYS, phase_time
from bench.truth.norms import scene_norm
from formulations import STATUS_OK

# relative energy-norm errors the combinations are ranked to
RELATIVE_TARGETS = (1e-2, 1e-3)
CANDIDATE_FACTOR = 1.3  # a sequence is timed again when within this factor of the fastest
MAX_CANDIDATES = 3  # per scene and target
LONG_SAMPLE = 2.0  # seconds: a candidate this long gets two samples, not ``repeats``
TIMINGS = "timings.parquet"  # in the results folder: one row per candidate, level and sample


@dataclass(frozen=True)
class Reach:
    """A sequence's first level at or below a relative error, and the time to get there."""

    scene: str
    target: float
    sequence_key: str
    level: int
    ndofs: int
    seconds: float


def measured(rows: pd.DataFrame) -> pd.DataFrame:
    """The solved levels with an error measured against a sharp enough truth."""
    return rows[(rows["status"] == STATUS_OK) & rows["energy_error"].gt(0)
                & ~rows["reference_too_coarse"].fillna(False).astype(bool)]


def reaches(rows: pd.DataFrame, norm: float, target: float) -> list[Reach]:
    """Every sequence of one scene that reaches ``target`` (``energy_error / norm``), with
    the cumulative time of its timed phases to that level, fastest first."""
    found = []
    for _, seq in measured(rows).sort_values("level").groupby(KEYS, sort=True, dropna=False):
        hit = np.flatnonzero(seq["energy_error"].to_numpy() / norm <= target)
        if hit.size:
            first = seq.iloc[hit[0]]
            found.append(Reach(str(first["scene"]), target, str(first["sequence_key"]),
                               int(first["level"]), int(first["ndofs"]),
                               float(phase_time(seq).cumsum().iloc[hit[0]])))
    return sorted(found, key=lambda r: r.seconds)


def candidates(table: pd.DataFrame, truth: dict) -> list[Reach]:
    """Per scene and target, the sequences within CANDIDATE_FACTOR of the fastest (at most
    MAX_CANDIDATES)."""
    rows = table[table["level"] >= 0]
    chosen = []
    for scene, group in rows.groupby("scene", sort=True):
        norm = scene_norm(str(scene), truth)
        for target in RELATIVE_TARGETS if norm else ():
            found = reaches(group, norm, target)
            chosen += [r for r in found[:MAX_CANDIDATES]
                       if r.seconds <= CANDIDATE_FACTOR * found[0].seconds]
    return chosen


def level_times(spec: SequenceSpec, last_level: int) -> np.ndarray:
    """The timed phases' seconds of levels 0..``last_level`` of ``spec``, run again without
    a truth or a cross-check."""
    loop = replace(spec.loop_config(), max_levels=last_level + 1)
    scene = build_scene(spec)
    warm_up(scene, spec)  # once per process: start-up costs are nobody's
    sequence = run_sequence(scene, spec.formulation, spec.solver, spec.estimator, loop,
                            formulation_options=dict(spec.formulation_options))
    rows = pd.DataFrame([vars(result.row) for result in sequence])
    return phase_time(rows).to_numpy()


def sample_rows(spec: SequenceSpec, level: int, repeats: int) -> pd.DataFrame:
    """``repeats`` samples of ``spec`` up to ``level`` (in the timing process)."""
    return pd.concat([_sample_rows(spec.key, k, np.cumsum(level_times(spec, level)))
                      for k in range(1, repeats + 1)], ignore_index=True)


def _start_timing_process(scene_files: tuple[str, ...]) -> None:
    load_plugins()
    load_scene_files(scene_files)


@contextmanager
def timing_process(scene_files: tuple[str, ...]):
    """One fresh process with one thread per library, as the matrix's workers have: the
    candidates run in it one after the other, so that no sample shares the machine with
    another and each sees the same threads (the driver's BLAS threads differ)."""
    saved = {name: os.environ.get(name) for name in SINGLE_THREAD}
    os.environ.update(SINGLE_THREAD)  # the process inherits the environment it starts with
    try:
        with ProcessPoolExecutor(1, mp_context=multiprocessing.get_context("spawn"),
                                 initializer=_start_timing_process,
                                 initargs=(scene_files,)) as pool:
            pool.submit(int).result()  # started now, with the environment above
            _restore(saved)
            yield pool
    finally:
        _restore(saved)


def _restore(saved: dict) -> None:
    for name, value in saved.items():
        if value is None:
            os.environ.pop(name, None)
        else:
            os.environ[name] = value


def time_again(specs: list[SequenceSpec], table: pd.DataFrame, truth: dict, repeats: int,
               on_sequence: Callable[[SequenceSpec, int], None] | None = None,
               scene_files: tuple[str, ...] = ()) -> pd.DataFrame:
    """The candidates' ``repeats`` samples (1, 2, ...; the matrix's own timing, which may
    have shared the machine with other workers, is not one), as rows of sequence_key,
    sample, level and the cumulative ``seconds`` to that level; ``on_sequence(spec, total)``
    after each of the ``total`` candidates."""
    by_key = {spec.key: spec for spec in specs}
    last: dict[str, int] = {}
    seconds: dict[str, float] = {}
    for r in candidates(table, truth):
        if r.sequence_key in by_key:
            last[r.sequence_key] = max(r.level, last.get(r.sequence_key, 0))
            seconds[r.sequence_key] = max(r.seconds, seconds.get(r.sequence_key, 0.0))
    samples = []
    with timing_process(scene_files) as pool:
        for key, level in last.items():
            times = min(repeats, 2) if seconds[key] >= LONG_SAMPLE else repeats
            samples.append(pool.submit(sample_rows, by_key[key], level, times).result())
            if on_sequence is not None:
                on_sequence(by_key[key], len(last))
    return pd.concat(samples, ignore_index=True) if samples else pd.DataFrame(
        columns=["sequence_key", "sample", "level", "seconds"])


def _sample_rows(key: str, sample: int, cumulative: np.ndarray) -> pd.DataFrame:
    return pd.DataFrame({"sequence_key": key, "sample": sample,
                         "level": np.arange(cumulative.size), "seconds": cumulative})


def truth_record(out: str | Path) -> dict:
    """The results folder's truth.json ({} without)."""
    path = Path(out) / "truth.json"
    return json.loads(path.read_text()) if path.exists() else {}


def write_timings(out: str | Path, samples: pd.DataFrame) -> Path:
    path = Path(out) / TIMINGS
    atomic_write(samples, path, "parquet")
    return path


def read_timings(out: str | Path | None) -> pd.DataFrame | None:
    """The samples of a results folder, or None where it has none."""
    path = Path(out) / TIMINGS if out is not None else None
    return pd.read_parquet(path) if path is not None and path.exists() else None

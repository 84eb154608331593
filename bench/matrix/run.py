"""The package's one entry point for running the matrix: a frozen ``RunConfig`` and
``run(config)``, called alike by the command line, ``compare``, ``verify`` and the tests.

A run is a list of ``SequenceSpec``: the cross product of scenes (each with its swept
parameters), formulations (each with its swept options), solvers, estimators and strategies.
A sequence finished by an earlier run into the same folder with the same spec is reused, not
recomputed, unless ``overwrite``."""

from __future__ import annotations

import sys
from collections.abc import Callable
from contextlib import suppress
from dataclasses import dataclass

import pandas as pd

from bench.matrix.config import RunConfig
from bench.matrix.cost import time_again, truth_record, write_timings
from bench.matrix.distributed import SchedulerError, check_scheduler
from bench.matrix.local import new_run_identity, run_specs, truth_name, write_truth_summary
from bench.matrix.provenance import write_run_record
from bench.matrix.rates import write_rates
from bench.matrix.spec import (
    SequenceSpec,
    build_scene,
    check_formulation_options,
    check_level_zero,
)
from bench.matrix.store import ResultStore
from bench.sequence.loop import LevelResult
from bench.sequence.rows import COLUMNS, ResultRow
from bench.truth import truth_for
from bench.truth.cache import CorruptCache, cache_folder, check_cache_folder, load_reference
from bench.truth.kinds import check_reference
from bench.truth.references import TruthError, reference_key
from formulations import STATUS_FAILED

# the default comparison's reference budget: 10 x its P3 part's 20 000 DOFs (measured on 2
# cores: paper 256 038 DOFs in 16 s, hertz about 220 000; the time of every error measured
# against a reference grows with its size, so no larger)
COMPARE_REFERENCE_DOFS = 260000
# ... and in 3D, where the reference is P2 (docs/theory.md, section 14.6): measured, 268 806
# and 206 736 DOFs on paper-3d and hertz-3d, error bars 0.98 % and 1.47 % of the energy norm,
# 117 s and 77 s; 10 x compare's 20 000 DOFs is what a P2 run would require
COMPARE_REFERENCE_DOFS_3D = 300000


def cached_reference_dofs(config: RunConfig) -> int | None:
    """The budget of the references ``compare`` caches (``COMPARE_REFERENCE_DOFS``, or the 3D
    one) when every scene of ``config`` without an exact solution has one cached there, so
    that ``run`` measures the errors ``compare`` measures without being told the budget;
    None when a scene has none (or no scene needs one)."""
    budgets, specs = set(), config.specs()
    for spec in {(s.scene, s.scene_parameters): s for s in specs}.values():
        scene = build_scene(spec)
        if scene.exact is not None:
            continue
        budget = compare_reference_dofs(None, scene.dim)
        key = reference_key(scene, budget)
        path = cache_folder(config.cache) / f"{key}.npz"
        try:  # one that could not judge these runs is not taken
            check_reference(load_reference(path, key), scene,
                            max(s.max_dofs for s in specs if s.scene == spec.scene),
                            max(s.order for s in specs if s.scene == spec.scene))
        except (OSError, CorruptCache, TruthError):
            return None
        budgets.add(budget)
    return budgets.pop() if len(budgets) == 1 else None


def compare_reference_dofs(given: int | None, dim: int) -> int:
    """The reference budget of compare: ``given`` (--reference-dofs), else the default of the
    scenes' dimension."""
    if given is not None:
        return given
    return {2: COMPARE_REFERENCE_DOFS, 3: COMPARE_REFERENCE_DOFS_3D}[dim]


@dataclass(frozen=True, eq=False)
class RunResult:
    rows: list[ResultRow]  # the rows this run computed
    table: pd.DataFrame  # every row of the run's sequences, reused ones included
    store: ResultStore
    reused: tuple[str, ...] = ()  # sequence keys taken from earlier runs

    @property
    def failed(self) -> list[ResultRow]:
        return [r for r in self.rows if r.status == STATUS_FAILED]


class RunRefused(ValueError):
    """A run refused before any sequence started: a bad sweep value or option, or a reference
    that cannot judge the runs (the message says which)."""


def prepare_truths(specs: list[SequenceSpec], crosscheck: bool = False,
                   max_memory_gib: float | None = None, cache=None) -> dict:
    """Every truth the specs need, built (or loaded) before any sequence runs, so that a bad
    scene parameter or formulation option, a starting mesh over the budgets, or a reference
    that cannot judge the runs, is refused first (RunRefused). Nothing is written."""
    try:
        return _truths(specs, crosscheck, max_memory_gib, cache)
    except ValueError as error:  # SceneError, TruthError, unknown parameters
        raise RunRefused(str(error)) from None


def _truths(specs: list[SequenceSpec], crosscheck: bool, max_memory_gib, cache) -> dict:
    judged = {}  # per truth: the largest budget and order it judges, and a spec to build it
    scenes, checked = {}, set()
    for spec in specs:
        check_formulation_options(spec)
        scene_key = (spec.scene, spec.scene_parameters)
        if scene_key not in scenes:
            scenes[scene_key] = build_scene(spec)
        option_key = (scene_key, spec.formulation, spec.formulation_options, spec.order)
        if option_key not in checked:
            check_level_zero(spec, scenes[scene_key], max_memory_gib)
            check_formulation_options(spec, scenes[scene_key])
            checked.add(option_key)
        dofs, order, first = judged.get(truth_name(spec), (0, 0, spec))
        judged[truth_name(spec)] = (max(dofs, spec.max_dofs), max(order, spec.order), first)
    truths = {}
    for name, (dofs, order, spec) in judged.items():
        truths[name] = truth_for(scenes[spec.scene, spec.scene_parameters],
                                 spec.reference_dofs, dofs, order, crosscheck, cache)
        if truths[name] is None:
            print(f"note: scene {spec.scene!r} has no exact solution and no reference budget "
                  "was given, so its errors and effectivity indices are not measured (NaN); "
                  "give --reference-dofs N (RunConfig.reference_dofs; compare uses "
                  f"{COMPARE_REFERENCE_DOFS}, {COMPARE_REFERENCE_DOFS_3D} in 3D) to measure "
                  "them against a cached overkill reference (P3; P2 on tetrahedra)",
                  file=sys.stderr)
    return truths


def check_before_running(config: RunConfig, specs: list[SequenceSpec]) -> dict:
    """Everything a run needs, checked before its folder is touched: the cache folder, the
    scheduler, every scene, option and starting mesh, and the truths (RunRefused). The
    truths, by name."""
    try:
        if config.cache is not None:
            check_cache_folder(config.cache)
        if config.scheduler:
            check_scheduler(config.scheduler)
    except (SchedulerError, ValueError) as error:
        raise RunRefused(str(error)) from None
    return prepare_truths(specs, config.reference_crosscheck, config.max_memory_gib,
                          config.cache)


def run(config: RunConfig, on_level: Callable[[LevelResult], None] | None = None,
        on_sequence: Callable[[SequenceSpec, str], None] | None = None,
        on_timed: Callable[[SequenceSpec, int], None] | None = None) -> RunResult:
    """Run every sequence of ``config`` into ``config.out``: sequences/ (a partition per
    sequence), results.{parquet,csv}, run.json, truth.json, artifacts/ and rates.{csv,md}.
    Raises RunRefused, with the folder untouched, for a bad parameter, a starting mesh over
    the budgets or an untrustworthy reference. With ``overwrite`` the earlier results are
    deleted only once a sequence of this run has finished, and kept if it fails before. With
    ``timing_repeats`` the candidates to be the cheapest are timed again (``bench.matrix.cost``,
    ``on_timed`` after each) into timings.parquet."""
    specs = config.specs()
    truths = check_before_running(config, specs)
    store = ResultStore(config.out, overwrite=config.overwrite)
    try:
        rows, reused = _run_into(store, config, specs, truths, on_level, on_sequence)
    except BaseException:  # a crash, Ctrl-C: the results moved aside come back
        store.restore_previous()
        with suppress(Exception):  # the tables say what the partitions hold (best effort)
            store.consolidate()
        raise
    store.keep_new()
    table = store.consolidate()
    write_rates(table, store.out)  # every sequence in the folder, earlier runs' too
    keys = {s.key for s in specs} | set(reused)
    table = table[table["sequence_key"].isin(keys)].reindex(columns=COLUMNS)
    if config.timing_repeats:
        write_timings(store.out, time_again(specs, table, truth_record(store.out),
                                            config.timing_repeats, on_timed,
                                            config.scene_files))
    return RunResult(rows, table.reset_index(drop=True), store, reused)


def _run_into(store: ResultStore, config: RunConfig, specs, truths, on_level, on_sequence):
    """The sequences of ``specs`` not finished in ``store`` yet: (rows, reused keys)."""
    finished = store.finished_keys()
    stored = {s.key: s.key if s.key in finished else s.legacy_key for s in specs}
    todo = [s for s in specs if stored[s.key] not in finished]
    reused = tuple(stored[s.key] for s in specs if stored[s.key] in finished)
    legacy = sum(stored[s.key] != s.key for s in specs if s not in todo)
    if legacy:
        print(f"note: {legacy} finished sequences in {store.out} are stored under the key of "
              "an earlier version of the package; they are reused as they are",
              file=sys.stderr)
    identity = new_run_identity()
    for name, truth in truths.items():  # truth.json then describes the whole table
        write_truth_summary(store.out, name, truth)
    write_run_record(store.out, config, identity["run_id"], reused)

    if config.workers or config.scheduler:
        from bench.matrix.distributed import run_on_dask

        rows = run_on_dask(todo, store, identity, config, on_sequence)
    else:
        rows = run_specs(todo, store, identity, on_level, truths, config.max_memory_gib,
                         on_sequence)
    return rows, reused

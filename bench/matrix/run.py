"""The package's one entry point for running the matrix: a frozen ``RunConfig`` and
``run(config)``, called alike by the command line, ``compare``, ``verify`` and the tests.

A run is a list of ``SequenceSpec``: the cross product of scenes (each with its swept
parameters), formulations (each with its swept options), solvers, estimators and strategies.
A sequence finished by an earlier run into the same folder with the same spec is reused, not
recomputed, unless ``overwrite``."""

from __future__ import annotations

import os
import sys
from collections.abc import Callable
from dataclasses import dataclass, fields

import pandas as pd

from bench.matrix.distributed import SchedulerError, check_scheduler, scheduler_endpoint
from bench.matrix.local import new_run_identity, run_specs, truth_name, write_truth_summary
from bench.matrix.plugins import load_plugins
from bench.matrix.provenance import write_run_record
from bench.matrix.rates import write_rates
from bench.matrix.scene_files import load_scene_files, source_digest
from bench.matrix.spec import (
    SequenceSpec,
    build_scene,
    check_formulation_options,
    check_level_zero,
    cross_product,
    parse_item,
)
from bench.matrix.store import ResultStore
from bench.sequence.loop import STRATEGIES, LevelResult, LoopConfig
from bench.sequence.rows import COLUMNS, ResultRow
from bench.truth import truth_for
from bench.truth.cache import check_cache_folder
from estimators import estimator_names, guaranteed_estimators
from formulations import STATUS_FAILED, formulation_names, solver_names
from formulations.cells import DEFAULT_CELL, cell_names, check_cell
from formulations.elasticity import ORDERS, check_order
from formulations.solvers.backends import check_backend
from formulations.solvers.registry import REFERENCE_SOLVER
from scenes import scene_names
from scenes.base import is_integer

NAME_LISTS = {"scenes": scene_names, "formulations": formulation_names,
              "solvers": solver_names, "estimators": estimator_names,
              "strategies": lambda: list(STRATEGIES)}
SWEPT = ("scenes", "formulations")  # lists whose items may carry name:key=v1|v2 sweeps
COMPARE_REFERENCE_DOFS = 200000  # the default comparison's reference budget
# ... and in 3D, where the reference is P2 (docs/theory.md, section 14.6): measured, 268 806
# and 206 736 DOFs on paper-3d and hertz-3d, error bars 0.98 % and 1.47 % of the energy norm,
# 117 s and 77 s; 10 x compare's 20 000 DOFs is what a P2 run would require
COMPARE_REFERENCE_DOFS_3D = 300000


def compare_reference_dofs(given: int | None, dim: int) -> int:
    """The reference budget of compare: ``given`` (--reference-dofs), else the default of the
    scenes' dimension."""
    if given is not None:
        return given
    return COMPARE_REFERENCE_DOFS_3D if dim == 3 else COMPARE_REFERENCE_DOFS


@dataclass(frozen=True)
class RunConfig:
    """Everything that determines a run of the matrix (the options of ``python -m bench run``).
    Name lists are checked against the registries on construction; a scene or formulation may
    carry a sweep, ``paper:poisson_ratio=0.3|0.45`` (docs/command-line.md)."""

    scenes: tuple[str, ...] = ("paper",)
    formulations: tuple[str, ...] = ("mixed",)
    solvers: tuple[str, ...] = (REFERENCE_SOLVER,)
    estimators: tuple[str, ...] = ("residual",)
    strategies: tuple[str, ...] = ("adaptive",)
    orders: tuple[int, ...] = (1,)  # polynomial orders of the displacements, a matrix dimension
    cells: tuple[str, ...] = (DEFAULT_CELL,)  # cell shapes (formulations.cells), a dimension
    max_dofs: int = 20000
    max_levels: int = 40
    marking: str = "doerfler"
    theta: float = 0.5
    backend: str | None = None
    nested: bool = True
    reference_dofs: int | None = None
    reference_crosscheck: bool = False  # also build the second recipe's reference, compare
    crosscheck_dofs: int = 0
    max_memory_gib: float | None = None  # None: what the machine has available, minus a margin
    out: str = "results"
    overwrite: bool = False
    workers: int = 0  # > 0: a local Dask cluster of this many processes
    scheduler: str | None = None  # the address of an existing Dask cluster
    cache: str | None = None  # reference cache folder (default $SIGNORINI_BENCH_CACHE)
    scene_files: tuple[str, ...] = ()  # Python files that register scenes (--scene-file)
    target_error: float | None = None  # stop each sequence once its guaranteed eta is below
    command: str = ""  # how the run was asked for, recorded in run.json

    def __post_init__(self):
        object.__setattr__(self, "scene_files", tuple(str(f) for f in self.scene_files))
        load_plugins()
        load_scene_files(self.scene_files)  # their scenes are valid names from here on
        for name, valid in NAME_LISTS.items():
            items = tuple(getattr(self, name))
            object.__setattr__(self, name, items)
            names = [item.split(":")[0] for item in items] if name in SWEPT else list(items)
            unknown = [n for n in names if n not in valid()]
            if not items or unknown:
                raise ValueError(f"{name}={list(items)!r}: unknown "
                                 f"{', '.join(unknown) or '(none)'}; valid: {', '.join(valid())}")
            if len(set(items)) < len(items):
                raise ValueError(f"{name}={list(items)!r} names an item twice")
            if name in SWEPT:
                for item in items:
                    parse_item(item, name)
        self._check_axis("orders", "order", list(map(str, ORDERS)), check_order)
        self._check_axis("cells", "cell", cell_names(), check_cell)
        for name in ("reference_dofs", "crosscheck_dofs", "workers"):
            value = getattr(self, name)
            if value is not None and not (is_integer(value) and value >= 0):
                raise ValueError(f"{name}={value!r} is not an integer >= 0")
        if self.backend is not None:
            check_backend(self.backend)
        if not str(self.out).strip():
            raise ValueError(f"out={self.out!r} is empty; give an output folder")
        if self.scheduler is not None:
            scheduler_endpoint(self.scheduler)
        unsafe = [e for e in self.estimators if e not in guaranteed_estimators()]
        if self.target_error is not None and unsafe:
            raise ValueError(f"target_error={self.target_error!r} needs estimators whose eta is "
                             f"a guaranteed bound ({', '.join(guaranteed_estimators())}); "
                             f"{', '.join(unsafe)} bound the error only up to a constant")
        self.loop()  # validates the loop's options

    def _check_axis(self, name: str, one: str, allowed: list[str], check) -> None:
        """A matrix axis (orders, cells): a non-empty tuple naming each value once, each one
        passing ``check``."""
        values = tuple(getattr(self, name))
        object.__setattr__(self, name, values)
        if not values or len(set(values)) < len(values):
            raise ValueError(f"{name}={list(values)!r}: give each {one} once, from "
                             f"{', '.join(allowed)}")
        for value in values:
            check(value)

    def specs(self) -> list[SequenceSpec]:
        return cross_product(
            [s for item in self.scenes for s in parse_item(item, "scenes")],
            [f for item in self.formulations for f in parse_item(item, "formulations")],
            self.solvers, self.estimators, self.strategies, self.orders, self.loop(),
            cells=self.cells,
            reference_dofs=self.reference_dofs, crosscheck_dofs=self.crosscheck_dofs,
            scene_source=source_digest(self.scene_files))

    def loop(self) -> LoopConfig:
        """The loop settings every sequence shares (LoopConfig validates them)."""
        return LoopConfig(strategy=self.strategies[0], order=self.orders[0],
                          max_dofs=self.max_dofs, max_levels=self.max_levels,
                          marking=self.marking, theta=self.theta, nested=self.nested,
                          target_error=self.target_error, max_memory_gib=self.max_memory_gib,
                          solver_options={"backend": self.backend} if self.backend else {})

    def record(self) -> dict:
        """The configuration as written to run.json."""
        return {f.name: getattr(self, f.name) for f in fields(self) if f.name != "command"}


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
                   max_memory_gib: float | None = None) -> dict:
    """Every truth the specs need, built (or loaded) before any sequence runs, so that a bad
    scene parameter or formulation option, a starting mesh over the budgets, or a reference
    that cannot judge the runs, is refused first (RunRefused). Nothing is written."""
    try:
        return _truths(specs, crosscheck, max_memory_gib)
    except ValueError as error:  # SceneError, TruthError, unknown parameters
        raise RunRefused(str(error)) from None


def _truths(specs: list[SequenceSpec], crosscheck: bool, max_memory_gib) -> dict:
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
                                 spec.reference_dofs, dofs, order, crosscheck)
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
    return prepare_truths(specs, config.reference_crosscheck, config.max_memory_gib)


def run(config: RunConfig, on_level: Callable[[LevelResult], None] | None = None,
        on_sequence: Callable[[SequenceSpec, str], None] | None = None) -> RunResult:
    """Run every sequence of ``config`` into ``config.out``: sequences/ (a partition per
    sequence), results.{parquet,csv}, run.json, truth.json, artifacts/ and rates.{csv,md}.
    Raises RunRefused, with the folder untouched, for a bad parameter, a starting mesh over
    the budgets or an untrustworthy reference. With ``overwrite`` the earlier results are
    deleted only once a sequence of this run has finished, and kept if it fails before."""
    specs = config.specs()
    truths = check_before_running(config, specs)
    if config.cache is not None:
        os.environ["SIGNORINI_BENCH_CACHE"] = str(config.cache)
    store = ResultStore(config.out, overwrite=config.overwrite)
    try:
        rows, reused = _run_into(store, config, specs, truths, on_level, on_sequence)
    except BaseException:  # a crash, Ctrl-C: the results moved aside come back
        store.restore_previous()
        raise
    store.keep_new()
    table = store.consolidate()
    write_rates(table, store.out)  # every sequence in the folder, earlier runs' too
    keys = {s.key for s in specs}
    table = table[table["sequence_key"].isin(keys)].reindex(columns=COLUMNS)
    return RunResult(rows, table.reset_index(drop=True), store, reused)


def _run_into(store: ResultStore, config: RunConfig, specs, truths, on_level, on_sequence):
    """The sequences of ``specs`` not finished in ``store`` yet: (rows, reused keys)."""
    finished = store.finished_keys()
    todo = [s for s in specs if s.key not in finished]
    reused = tuple(s.key for s in specs if s.key in finished)
    identity = new_run_identity()
    for name, truth in truths.items():  # truth.json then describes the whole table
        write_truth_summary(store.out, name, truth)
    write_run_record(store.out, config, identity["run_id"], reused)

    def sequence_done(spec: SequenceSpec, end: str) -> None:
        store.keep_new()  # a sequence of this run finished: the old results may go
        if on_sequence is not None:
            on_sequence(spec, end)

    if config.workers or config.scheduler:
        from bench.matrix.distributed import run_on_dask

        rows = run_on_dask(todo, store, identity, config, sequence_done)
    else:
        rows = run_specs(todo, store, identity, on_level, truths, config.max_memory_gib,
                         sequence_done)
    return rows, reused

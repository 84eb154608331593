"""The package's one entry point for running the matrix: a frozen ``RunConfig`` and
``run(config)``, called alike by the command line, ``compare``, ``verify`` and the tests."""

from __future__ import annotations

import json
from collections.abc import Callable
from dataclasses import dataclass, fields

import pandas as pd

from bench.matrix.harness import run_matrix
from bench.matrix.rates import write_rates
from bench.matrix.store import ResultStore
from bench.sequence.loop import STRATEGIES, LevelResult, LoopConfig
from bench.sequence.rows import ResultRow
from bench.truth import truth_for
from estimators import estimator_names
from formulations import STATUS_FAILED, formulation_names, solver_names
from formulations.solvers.backends import check_backend
from scenes import get_scene, scene_names
from scenes.base import is_integer

NAME_LISTS = {"scenes": scene_names, "formulations": formulation_names,
              "solvers": solver_names, "estimators": estimator_names,
              "strategies": lambda: list(STRATEGIES)}


@dataclass(frozen=True)
class RunConfig:
    """Everything that determines a run of the matrix (the options of ``python -m bench run``).
    Name lists are checked against the registries on construction."""

    scenes: tuple[str, ...] = ("paper",)
    formulations: tuple[str, ...] = ("mixed",)
    solvers: tuple[str, ...] = ("reference",)
    estimators: tuple[str, ...] = ("residual",)
    strategies: tuple[str, ...] = ("adaptive",)
    max_dofs: int = 20000
    max_levels: int = 40
    marking: str = "doerfler"
    theta: float = 0.5
    backend: str | None = None
    nested: bool = True
    reference_dofs: int | None = None
    crosscheck_dofs: int = 0
    max_memory_gib: float | None = None  # None: what the machine has available, minus a margin
    out: str = "results"
    overwrite: bool = False
    command: str = ""  # how the run was asked for, recorded in run.json

    def __post_init__(self):
        for name, valid in NAME_LISTS.items():
            names = tuple(getattr(self, name))
            object.__setattr__(self, name, names)
            unknown = [n for n in names if n not in valid()]
            if not names or unknown:
                raise ValueError(f"{name}={list(names)!r}: unknown {', '.join(unknown) or '(none)'}"
                                 f"; valid: {', '.join(valid())}")
        for name in ("reference_dofs", "crosscheck_dofs"):
            value = getattr(self, name)
            if value is not None and not (is_integer(value) and value >= 0):
                raise ValueError(f"{name}={value!r} is not an integer >= 0")
        if self.backend is not None:
            check_backend(self.backend)
        self.loop_config(self.strategies[0])  # validates the loop's options

    def loop_config(self, strategy: str) -> LoopConfig:
        return LoopConfig(strategy=strategy, max_dofs=self.max_dofs, max_levels=self.max_levels,
                          marking=self.marking, theta=self.theta, nested=self.nested,
                          solver_options={"backend": self.backend} if self.backend else {},
                          max_memory_gib=self.max_memory_gib)

    def record(self) -> dict:
        """The configuration as written to run.json."""
        return {f.name: getattr(self, f.name) for f in fields(self) if f.name != "command"}


@dataclass(frozen=True, eq=False)
class RunResult:
    rows: list[ResultRow]
    table: pd.DataFrame  # this run's rows
    store: ResultStore

    @property
    def failed(self) -> list[ResultRow]:
        return [r for r in self.rows if r.status == STATUS_FAILED]


def run(config: RunConfig, on_level: Callable[[LevelResult], None] | None = None) -> RunResult:
    """Run every combination of ``config`` into ``config.out``: results.{parquet,csv} (each
    level as it finishes), run.json, truth.json, artifacts/ and rates.{csv,md}. Raises
    ``bench.truth.TruthError`` before any run if a reference cannot judge the runs."""
    # every truth first: a reference that cannot judge these runs is refused before any run
    truths = {name: truth_for(get_scene(name), config.reference_dofs, config.max_dofs)
              for name in config.scenes}
    store = ResultStore(config.out, overwrite=config.overwrite)
    (store.out / "run.json").write_text(json.dumps(
        {"command": config.command, "configuration": config.record()}, indent=1, default=str))
    rows = run_matrix(config.scenes, config.formulations, config.solvers, config.estimators,
                      config.strategies, store, config.loop_config(config.strategies[0]),
                      on_level=on_level, reference_dofs=config.reference_dofs,
                      crosscheck_dofs=config.crosscheck_dofs, truths=truths)
    table = store.run_table()
    write_rates(table, store.out)
    return RunResult(rows, table, store)


__all__ = ["RunConfig", "RunResult", "run"]

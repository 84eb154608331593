"""The rate study (docs/theory.md, section 10): uniform sequences to about 2e6 DOFs and
adaptive ones to 1e6 for every formulation x estimator on the study's scenes, errors against
exact solutions or the P3 references, then the study's report. Resumable: the rows go to an
ordinary result store, and a rerun reuses every finished sequence."""

from __future__ import annotations

import time
from dataclasses import dataclass, replace
from pathlib import Path

import pandas as pd

from bench.matrix import RunConfig, run
from bench.matrix.config_files import dataclass_fields, read_toml
from bench.matrix.store import ResultStore
from bench.sequence.options import option
from bench.sequence.rows import FINISHED
from bench.study.report import write_study_report
from bench.verify import load_expected
from estimators import estimator_names
from formulations import formulation_names
from formulations.cells import DEFAULT_CELL, cell_names, check_cell
from formulations.solvers.registry import FAST_SOLVER

STUDY_SETTINGS = Path(__file__).with_name("study.toml")  # the defaults, and [quick]
STUDY_KEYS = ["scenes", "orders", "uniform_max_dofs", "adaptive_max_dofs", "reference_dofs",
              "workers", "crosscheck", "out", "report", "cell", "formulations", "estimators"]


def _study_tables(path: str | Path) -> tuple[dict, dict, dict]:
    """A study file's settings, its ``[quick]`` table's and its ``[cells.NAME]`` tables' (each
    with its own ``quick`` table), as ``StudyConfig`` fields."""
    data = read_toml(path, "a study file")
    quick, cells = data.pop("quick", {}), data.pop("cells", {})
    where = f"config={str(path)!r}"

    def fields(table: dict, name: str) -> dict:
        return dataclass_fields(table, STUDY_KEYS, f"{where} [{name}]")

    return (fields(data, "top"), fields(quick, "quick"),
            {cell: (fields({k: v for k, v in table.items() if k != "quick"}, f"cells.{cell}"),
                    fields(table.get("quick", {}), f"cells.{cell}.quick"))
             for cell, table in cells.items()})


_SETTINGS = _study_tables(STUDY_SETTINGS)[0]


def _study(key: str, help: str, flag: str, kind: str, section: str = "what", **more):
    """A study setting that is also an option of ``python -m bench study``, its default the
    package's study.toml."""
    return option(_SETTINGS[key], help, flag=flag, kind=kind, section=section, **more)


@dataclass(frozen=True)
class StudyConfig:
    """The rate study's settings; the defaults are the package's ``study.toml``."""

    scenes: tuple[str, ...] = _study(
        "scenes", "scene(s)", "scene", "scenes",
        default_text="the study file's; with --cell quad or hex: its [cells.NAME] table's")
    orders: tuple[int, ...] = _study("orders", "polynomial order(s)", "order", "orders")
    uniform_max_dofs: int = _study("uniform_max_dofs", "DOF budget of the uniform sequences",
                                   "uniform-max-dofs", "int>0")
    adaptive_max_dofs: int = _study("adaptive_max_dofs",
                                    "DOF budget of the adaptive sequences",
                                    "adaptive-max-dofs", "int>0")
    reference_dofs: int = _study("reference_dofs", "P3 reference budget", "reference-dofs",
                                 "int>0")
    workers: int = _study("workers", "adaptive sequences run in parallel on a local Dask "
                          "cluster of this many processes; uniform ones one at a time",
                          "workers", "int>=0", section="where")
    crosscheck: bool = _SETTINGS["crosscheck"]  # the P2 references too, compared in truth.json
    out: str = _study("out", "results folder", "out", "text", section="where")
    report: str = _study("report", "report folder", "report", "text", section="where")
    cell: str = _SETTINGS.get("cell", DEFAULT_CELL)  # the matrix's cell axis (one shape)
    # () runs every registered formulation, or estimator
    formulations: tuple[str, ...] = _SETTINGS.get("formulations", ())
    estimators: tuple[str, ...] = _SETTINGS.get("estimators", ())
    command: str = "python -m bench study"

    def run_configs(self) -> list[RunConfig]:
        """Adaptive first (in parallel, about 5 GiB each at 1e6 DOFs), then uniform in this
        process (a 2.1e6-DOF level needs about 11 GiB, half of a 24 GiB machine)."""
        common = dict(scenes=self.scenes, solvers=(FAST_SOLVER,), cells=(self.cell,),
                      estimators=self.estimators or tuple(estimator_names()), orders=self.orders,
                      reference_dofs=self.reference_dofs, reference_crosscheck=self.crosscheck,
                      out=self.out, command=self.command)
        formulations = self.formulations or tuple(formulation_names())
        return [RunConfig(strategies=("adaptive",), max_dofs=self.adaptive_max_dofs,
                          workers=self.workers, formulations=formulations, **common),
                RunConfig(strategies=("uniform",), max_dofs=self.uniform_max_dofs,
                          formulations=formulations, **common)]


@dataclass(frozen=True)
class StudyFile:
    """A study file: its settings, and what ``[quick]`` and each ``[cells.NAME]`` replace."""

    settings: StudyConfig
    quick: tuple[tuple[str, object], ...] = ()
    # per cell name: its table's settings and its quick table's
    cells: tuple[tuple[str, tuple, tuple], ...] = ()

    def cell_names(self) -> list[str]:
        """What ``--cell`` takes: the matrix's cell shapes and the file's ``[cells.NAME]``."""
        return sorted({*cell_names(), *(name for name, _, _ in self.cells)})

    def config(self, cell: str | None = None, quick: bool = False) -> StudyConfig:
        """The study on ``cell`` (default: the file's): its ``[cells.NAME]`` table (whose own
        ``cell`` key, if any, is the matrix's cell axis: ``hex`` runs ``quad`` cells on 3D
        scenes), reduced to ``[quick]`` if asked."""
        name = cell or self.settings.cell
        tables = {cell: (table, reduced) for cell, table, reduced in self.cells}
        if name not in self.cell_names():
            raise ValueError(f"cell={name!r} is not one of {', '.join(self.cell_names())}")
        table, reduced = tables.get(name, ((), ()))
        config = replace(self.settings, cell=name, **(dict(self.quick) if quick else {}))
        config = replace(config, **{**dict(table), **(dict(reduced) if quick else {})})
        return replace(config, cell=check_cell(config.cell))


def read_study_file(path: str | Path = STUDY_SETTINGS) -> StudyFile:
    """A study file (the package's study.toml, or a copy given with ``--config``)."""
    settings, quick, cells = _study_tables(path)
    return StudyFile(StudyConfig(**settings), tuple(quick.items()),
                     tuple((cell, tuple(table.items()), tuple(reduced.items()))
                           for cell, (table, reduced) in cells.items()))


# the default tests' version: the paper scene to a few thousand DOFs
STUDY_FILE = read_study_file()
QUICK = STUDY_FILE.config(quick=True)


def study_gates(config: StudyConfig) -> list[dict] | None:
    """The ``[[study_gate]]`` entries for the scenes and orders of a study with the full
    budgets, None for a reduced one (its slopes are pre-asymptotic)."""
    full = StudyConfig()
    if (config.uniform_max_dofs < full.uniform_max_dofs
            or config.adaptive_max_dofs < full.adaptive_max_dofs):
        return None
    return [gate for gate in load_expected().get("study_gate", [])
            if gate.get("cell", DEFAULT_CELL) == config.cell
            and gate.get("scene", config.scenes[0]) in config.scenes
            and gate.get("order", config.orders[0]) in config.orders]


def run_study(config: StudyConfig, on_level=None) -> tuple[pd.DataFrame, object, list]:
    """Run (or reuse) every sequence of the study, then write its report; returns the rows,
    the report's path and the verdicts of the study's gates."""
    start = time.perf_counter()
    tables = []
    for run_config in config.run_configs():
        tables.append(run(run_config, on_level=on_level).table)
    table = pd.concat(tables, ignore_index=True)
    report, verdicts = write_study_report(
        table, config.report, time.perf_counter() - start,
        planned=table.groupby("sequence_key").ngroups, gates=study_gates(config),
        results=config.out)
    return table, report, verdicts


def finished_table(config: StudyConfig) -> tuple[pd.DataFrame, int]:
    """The rows of the study's sequences finished so far in ``config.out`` (another process may
    still be running the rest), and how many sequences the study plans."""
    specs = [spec for run_config in config.run_configs() for spec in run_config.specs()]
    keys = {spec.key for spec in specs} | {spec.legacy_key for spec in specs}
    table = ResultStore(config.out).table()
    done = table["sequence_key"].isin(keys) & table["sequence_end"].isin(FINISHED)
    return table[done].reset_index(drop=True), len(specs)


def report_study(config: StudyConfig) -> tuple[pd.DataFrame, object, list]:
    """The report of what is finished, without running anything."""
    table, planned = finished_table(config)
    if table.empty:
        raise ValueError(f"out={config.out!r} holds no finished sequence of this study")
    report, verdicts = write_study_report(table, config.report, planned=planned,
                                          gates=study_gates(config), results=config.out)
    return table, report, verdicts

"""The rate study (docs/theory.md, section 10): uniform sequences to about 2e6 DOFs and
adaptive ones to 1e6 for every formulation x estimator on the study's scenes, errors against
exact solutions or the P3 references, then the study's report. Resumable: the rows go to an
ordinary result store, and a rerun reuses every finished sequence."""

from __future__ import annotations

import time
from dataclasses import dataclass

import pandas as pd

from bench.matrix import RunConfig, run
from bench.matrix.store import ResultStore
from bench.sequence.rows import FINISHED
from bench.study.report import write_study_report
from bench.verify import load_expected
from estimators import estimator_names
from formulations import formulation_names
from formulations.solvers.registry import FAST_SOLVER


@dataclass(frozen=True)
class StudyConfig:
    scenes: tuple[str, ...] = ("paper", "free-boundary", "hertz")
    orders: tuple[int, ...] = (1,)
    uniform_max_dofs: int = 2_100_000
    adaptive_max_dofs: int = 1_000_000
    reference_dofs: int = 200_000
    workers: int = 2  # adaptive sequences in parallel; uniform ones run one at a time
    crosscheck: bool = True  # build the P2 references too; truth.json records the agreement
    out: str = "study"
    report: str = "reports/study"
    command: str = "python -m bench study"

    def run_configs(self) -> list[RunConfig]:
        """Adaptive first (in parallel, about 5 GiB each at 1e6 DOFs), then uniform in this
        process (a 2.1e6-DOF level needs about 11 GiB, half of a 24 GiB machine)."""
        common = dict(scenes=self.scenes, solvers=(FAST_SOLVER,),
                      estimators=tuple(estimator_names()), orders=self.orders,
                      reference_dofs=self.reference_dofs, reference_crosscheck=self.crosscheck,
                      out=self.out, command=self.command)
        formulations = tuple(formulation_names())
        return [RunConfig(strategies=("adaptive",), max_dofs=self.adaptive_max_dofs,
                          workers=self.workers, formulations=formulations, **common),
                RunConfig(strategies=("uniform",), max_dofs=self.uniform_max_dofs,
                          formulations=formulations, **common)]


# the default tests' version: the paper scene to a few thousand DOFs
QUICK = StudyConfig(scenes=("paper",), uniform_max_dofs=9000, adaptive_max_dofs=5000,
                    workers=0, crosscheck=False)


def study_gates(config: StudyConfig) -> list[dict] | None:
    """The ``[[study_gate]]`` entries for the scenes and orders of a study with the full
    budgets, None for a reduced one (its slopes are pre-asymptotic)."""
    full = StudyConfig()
    if (config.uniform_max_dofs < full.uniform_max_dofs
            or config.adaptive_max_dofs < full.adaptive_max_dofs):
        return None
    return [gate for gate in load_expected().get("study_gate", [])
            if gate.get("scene", config.scenes[0]) in config.scenes
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
        planned=table.groupby("sequence_key").ngroups, gates=study_gates(config))
    return table, report, verdicts


def finished_table(config: StudyConfig) -> tuple[pd.DataFrame, int]:
    """The rows of the study's sequences finished so far in ``config.out`` (another process may
    still be running the rest), and how many sequences the study plans."""
    keys = {spec.key for run_config in config.run_configs() for spec in run_config.specs()}
    table = ResultStore(config.out).table()
    done = table["sequence_key"].isin(keys) & table["sequence_end"].isin(FINISHED)
    return table[done].reset_index(drop=True), len(keys)


def report_study(config: StudyConfig) -> tuple[pd.DataFrame, object, list]:
    """The report of what is finished, without running anything."""
    table, planned = finished_table(config)
    if table.empty:
        raise ValueError(f"out={config.out!r} holds no finished sequence of this study")
    report, verdicts = write_study_report(table, config.report, planned=planned,
                                          gates=study_gates(config))
    return table, report, verdicts

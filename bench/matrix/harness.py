"""The matrix harness: every (scene, formulation, solver, estimator, strategy) sequence of a
run, in this process (``run_specs``); ``bench.matrix.distributed`` runs the same specs on Dask."""

from __future__ import annotations

import json
import secrets
import time
from collections.abc import Callable, Sequence
from pathlib import Path

from bench.matrix.provenance import provenance
from bench.matrix.spec import SequenceSpec, cross_product
from bench.matrix.store import ResultStore
from bench.matrix.task import run_spec
from bench.sequence.loop import LevelResult, LoopConfig
from bench.sequence.rows import INTERRUPTED, ResultRow
from bench.truth import truth_for


def new_run_identity() -> dict:
    """The run's columns: a unique run id (time, then random hex) and the provenance."""
    return {"run_id": time.strftime("%Y%m%dT%H%M%S-") + secrets.token_hex(3), **provenance()}


def truth_name(spec: SequenceSpec) -> str:
    return spec.scene + (f":{spec.labels['scene_parameters']}"
                         if spec.scene_parameters else "")


def write_truth_summary(out, name: str, truth) -> None:
    """``truth.json``: per scene, what errors were measured against (reference summary)."""
    path = Path(out) / "truth.json"
    summary = json.loads(path.read_text()) if path.exists() else {}
    if truth is None:
        summary[name] = {"kind": "none"}
    elif truth.kind == "reference":
        summary[name] = {"kind": "reference", **truth.reference.summary()}
        if truth.crosscheck is not None:
            summary[name]["crosscheck"] = truth.crosscheck.summary()
    else:
        summary[name] = {"kind": "exact", "source": truth.scene.exact.source}
    path.write_text(json.dumps(summary, indent=1, default=float))


def specs_for(scenes: Sequence[str], formulations: Sequence[str], solvers: Sequence[str],
              estimators: Sequence[str], strategies: Sequence[str], config: LoopConfig,
              reference_dofs: int | None = None, crosscheck_dofs: int = 0,
              scene_parameters: dict | None = None) -> list[SequenceSpec]:
    """The cross product as specs (``config`` gives the loop settings)."""
    parameters = tuple((scene_parameters or {}).items())
    return cross_product([(s, parameters) for s in scenes], [(f, ()) for f in formulations],
                         solvers, estimators, strategies, max_dofs=config.max_dofs,
                         max_levels=config.max_levels, marking=config.marking,
                         theta=config.theta, nested=config.nested,
                         backend=config.solver_options.get("backend"),
                         reference_dofs=reference_dofs, crosscheck_dofs=crosscheck_dofs)


def run_specs(specs: Sequence[SequenceSpec], store: ResultStore, run: dict,
              on_level: Callable[[LevelResult], None] | None = None,
              truths: dict | None = None, max_memory_gib: float | None = None,
              on_sequence: Callable[[SequenceSpec, str], None] | None = None) -> list[ResultRow]:
    """Run the specs one after another in this process; each finished level is stored at
    once, each sequence's end reason when it ends (``interrupted`` on Ctrl-C, which is then
    raised again). ``truths`` (by ``truth_name``) are built as needed when missing."""
    rows, truths = [], dict(truths or {})

    def record(result: LevelResult) -> None:
        store.append(result.row)
        rows.append(result.row)
        if on_level is not None:
            on_level(result)

    for spec in specs:
        name = truth_name(spec)

        def truth_of(scene, name=name, spec=spec):
            if name not in truths:  # run() prepares them; run_matrix builds them here
                truths[name] = truth_for(scene, spec.reference_dofs, spec.max_dofs,
                                         spec.order)
                write_truth_summary(store.out, name, truths[name])
            return truths[name]
        try:
            end = run_spec(spec, run, store.out, truth_of, record, max_memory_gib)
        except KeyboardInterrupt:
            store.finish(spec.key, INTERRUPTED)
            raise
        store.finish(spec.key, end)
        if on_sequence is not None:
            on_sequence(spec, end)
    return rows


def run_matrix(scenes: Sequence[str], formulations: Sequence[str], solvers: Sequence[str],
               estimators: Sequence[str], strategies: Sequence[str], store: ResultStore,
               config: LoopConfig, on_level: Callable[[LevelResult], None] | None = None,
               scene_parameters: dict | None = None, reference_dofs: int | None = None,
               crosscheck_dofs: int = 0) -> list[ResultRow]:
    """Run the cross product in this process (see ``run_specs``): errors against each
    scene's exact solution or an overkill reference of ``reference_dofs`` DOFs; levels with at
    most ``crosscheck_dofs`` DOFs also solved by the reference solver; the last level of each
    sequence saved as an artifact (``bench.matrix.artifacts``)."""
    specs = specs_for(scenes, formulations, solvers, estimators, strategies, config,
                      reference_dofs, crosscheck_dofs, scene_parameters)
    return run_specs(specs, store, new_run_identity(), on_level,
                     max_memory_gib=config.max_memory_gib)

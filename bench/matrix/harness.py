"""The matrix harness: every (scene, formulation, solver, estimator, strategy) combination."""

from __future__ import annotations

import itertools
import json
import time
import traceback
from collections.abc import Callable, Sequence
from dataclasses import replace
from pathlib import Path

from bench.matrix.artifacts import save_artifact
from bench.matrix.provenance import provenance
from bench.matrix.store import ResultStore
from bench.sequence.loop import LevelResult, LoopConfig, run_sequence
from bench.sequence.rows import ResultRow, identity_columns
from bench.truth import truth_for
from estimators.base import ESTIMATORS
from formulations import STATUS_FAILED, STATUS_SKIPPED
from formulations.registry import FORMULATIONS
from formulations.solvers.registry import SOLVERS
from scenes import Scene, get_scene


def why_skipped(scene: Scene, formulation: str, solver: str, estimator: str) -> str | None:
    """The reason a combination is impossible (declared by the registrations), or None."""
    return (FORMULATIONS.why_not(formulation, scene=scene)
            or SOLVERS.why_not(solver, scene=scene, formulation=formulation)
            or ESTIMATORS.why_not(estimator, scene=scene, formulation=formulation))


def _write_truth_summary(out, scene_name: str, truth) -> None:
    """``truth.json``: per scene, what errors were measured against (reference summary)."""
    path = Path(out) / "truth.json"
    summary = json.loads(path.read_text()) if path.exists() else {}
    if truth is None:
        summary[scene_name] = {"kind": "none"}
    elif truth.kind == "reference":
        summary[scene_name] = {"kind": "reference", **truth.reference.summary()}
    else:
        summary[scene_name] = {"kind": "exact", "source": truth.scene.exact.source}
    path.write_text(json.dumps(summary, indent=1, default=float))


def _whole_run_row(names: dict, status: str, reason: str) -> LevelResult:
    """One row (level -1) standing for a whole combination that was skipped or crashed."""
    return LevelResult(ResultRow(level=-1, status=status, reason=reason, **names), None, None)


def run_matrix(scenes: Sequence[str], formulations: Sequence[str], solvers: Sequence[str],
               estimators: Sequence[str], strategies: Sequence[str], store: ResultStore,
               config: LoopConfig, on_level: Callable[[LevelResult], None] | None = None,
               scene_parameters: dict | None = None,
               reference_dofs: int | None = None,
               crosscheck_dofs: int = 0, truths: dict | None = None) -> list[ResultRow]:
    """Run the cross product; each finished level is stored at once. An exception inside one
    combination becomes a ``failed`` row with the reason, and the next combination runs; an
    impossible combination becomes one ``skipped`` row with the reason. Errors are measured
    against each scene's exact solution, or an overkill reference of ``reference_dofs`` DOFs
    (``bench.truth``; None and no exact solution: no errors; ``truths`` may hold them already,
    by scene name). Levels with at most
    ``crosscheck_dofs`` DOFs are also solved by the reference solver for comparison. The last
    level of every combination is saved as an artifact (``bench.matrix.artifacts``) for the
    report."""
    run_id = time.strftime("%Y%m%dT%H%M%S")
    identity = {"run_id": run_id, **provenance()}
    rows, truths = [], dict(truths or {})

    def record(result: LevelResult) -> None:
        store.append(result.row)
        rows.append(result.row)
        if on_level is not None:
            on_level(result)

    for scene_name, formulation, solver, estimator, strategy in itertools.product(
            scenes, formulations, solvers, estimators, strategies):
        cfg = replace(config, strategy=strategy)
        names = identity_columns(scene_name, formulation, solver, estimator, cfg, identity)
        try:
            scene = get_scene(scene_name, **(scene_parameters or {}))
            reason = why_skipped(scene, formulation, solver, estimator)
            if reason is not None:
                record(_whole_run_row(names, STATUS_SKIPPED, reason))
                continue
            if scene_name not in truths:
                truths[scene_name] = truth_for(scene, reference_dofs, config.max_dofs)
            _write_truth_summary(store.out, scene_name, truths[scene_name])
            last = None
            for result in run_sequence(scene, formulation, solver, estimator, cfg, identity,
                                       truth=truths[scene_name], crosscheck_dofs=crosscheck_dofs):
                record(result)
                last = result if result.solution is not None else last
            if last is not None:
                save_artifact(store.out, last)
        except Exception as error:  # recorded, never silent: the row carries type and message
            record(_whole_run_row(names, STATUS_FAILED, f"{type(error).__name__}: {error}"))
            traceback.print_exc()
    return rows

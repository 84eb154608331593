"""The matrix harness: every (scene, formulation, solver, estimator, strategy) combination."""

from __future__ import annotations

import itertools
import time
import traceback
from collections.abc import Callable, Sequence
from dataclasses import replace

from bench.loop import LevelResult, LoopConfig, run_sequence
from bench.provenance import provenance
from bench.rows import ResultRow
from bench.store import ResultStore
from formulations import STATUS_FAILED
from scenes import get_scene


def run_matrix(scenes: Sequence[str], formulations: Sequence[str], solvers: Sequence[str],
               estimators: Sequence[str], strategies: Sequence[str], store: ResultStore,
               config: LoopConfig, on_level: Callable[[LevelResult], None] | None = None,
               scene_parameters: dict | None = None) -> list[ResultRow]:
    """Run the cross product; each finished level is stored at once. An exception inside one
    combination becomes a ``failed`` row with the reason, and the next combination runs."""
    run_id = time.strftime("%Y%m%dT%H%M%S")
    identity = {"run_id": run_id, **provenance()}
    rows = []
    for scene_name, formulation, solver, estimator, strategy in itertools.product(
            scenes, formulations, solvers, estimators, strategies):
        cfg = replace(config, strategy=strategy)
        try:
            scene = get_scene(scene_name, **(scene_parameters or {}))
            for result in run_sequence(scene, formulation, solver, estimator, cfg, identity):
                store.append(result.row)
                rows.append(result.row)
                if on_level is not None:
                    on_level(result)
        except Exception as error:  # recorded, never silent: the row carries type and message
            row = ResultRow(scene=scene_name, formulation=formulation, solver=solver,
                            estimator=estimator, strategy=strategy, level=-1,
                            status=STATUS_FAILED, reason=f"{type(error).__name__}: {error}",
                            marking=cfg.marking, theta=cfg.theta, **identity)
            store.append(row)
            rows.append(row)
            if on_level is not None:
                on_level(LevelResult(row, None, None))
            traceback.print_exc()
    return rows

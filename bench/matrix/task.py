"""One sequence of a run as a task: build its scene, run it, record every level, and return
why it ended. The same function runs in-process and on a Dask worker."""

from __future__ import annotations

import sys
import traceback
from collections.abc import Callable
from dataclasses import dataclass, replace

from bench.matrix.artifacts import level_artifact_path, publish_last_level, save_artifact
from bench.matrix.files import FULL
from bench.matrix.spec import SequenceSpec, build_scene, check_formulation_options
from bench.sequence.goal import why_no_goal
from bench.sequence.loop import LevelResult, run_sequence
from bench.sequence.rows import ResultRow, identity_columns
from estimators.base import ESTIMATORS, why_not_on
from formulations import STATUS_FAILED, STATUS_SKIPPED
from formulations.cells import DEFAULT_CELL, family_for
from formulations.discretisation import why_unsolvable
from formulations.elasticity import why_no_element
from formulations.registry import FORMULATIONS, get_formulation
from formulations.solvers.registry import SOLVERS
from scenes import Scene


@dataclass(frozen=True)
class Outcome:
    key: str
    end: str
    rows: tuple[ResultRow, ...] = ()


def why_skipped(scene: Scene, formulation: str, solver: str, estimator: str,
                options: dict | None = None, order: int = 1, cell: str = DEFAULT_CELL,
                strategy: str = "uniform", goal: str | None = None) -> str | None:
    """The reason a combination is impossible (declared by the registrations and the cell
    family, or no method of the solver for the problem the formulation offers with these
    options), or None."""
    try:
        family = family_for(cell, scene.dim)
    except ValueError as error:
        return str(error)
    reason = (family.why_not(scene, strategy) or why_no_element(order, scene.dim, cell)
              or FORMULATIONS.why_not(formulation, scene=scene, family=family)
              or (SOLVERS.why_not(solver, scene=scene, formulation=formulation)
                  if solver in SOLVERS.names() else None)
              or ESTIMATORS.why_not(estimator, scene=scene, formulation=formulation)
              or why_not_on(estimator, family)
              or why_no_goal(scene, goal, strategy, order, family))
    if reason is not None:
        return reason
    coarse = get_formulation(formulation)(scene, family.starting_mesh(scene), order=order,
                                          **(options or {}))
    return why_unsolvable(coarse, solver)


def run_columns(spec: SequenceSpec, run: dict) -> dict:
    """The run's identity columns with the spec's sweep labels and key."""
    return {**run, **spec.labels, "sequence_key": spec.key}


def sequence_identity(spec: SequenceSpec, run: dict) -> dict:
    return identity_columns(spec.scene, spec.formulation, spec.solver, spec.estimator,
                            spec.loop_config(), run_columns(spec, run))


def drain(sequence, record: Callable[[LevelResult], None]) -> tuple[str, LevelResult | None]:
    """Record every level of a ``run_sequence`` generator; its end reason and last solved
    level."""
    last = None
    while True:
        try:
            result = next(sequence)
        except StopIteration as stop:
            return stop.value, last
        record(result)
        last = result if result.solution is not None else last


def run_spec(spec: SequenceSpec, run: dict, out, truth_of: Callable[[Scene], object],
             record: Callable[[LevelResult], None], max_memory_gib: float | None = None) -> str:
    """Run ``spec`` (``run``: the run's identity columns; ``truth_of(scene)``: its truth);
    every level goes to ``record`` and its fields to a level artifact; the last solved level
    is also saved as the combination's artifact. An
    impossible combination is one ``skipped`` row, an exception one ``failed`` row (level -1)
    with its type and message. Returns why the sequence ended."""
    names = sequence_identity(spec, run)
    try:
        scene = build_scene(spec)
        check_formulation_options(spec)
        names["dim"] = scene.dim
        names["cell"] = spec.cell
        reason = why_skipped(scene, spec.formulation, spec.solver, spec.estimator,
                             dict(spec.formulation_options), spec.order, spec.cell,
                             spec.strategy, spec.loop_config().goal)
        if reason is not None:
            record(whole_sequence_row(names, STATUS_SKIPPED, reason))
            return STATUS_SKIPPED  # also its end reason

        def record_level(result: LevelResult) -> None:
            record(result)
            if result.solution is not None:
                save_artifact(level_artifact_path(out, result.row), result, scene)

        warm_up(scene, spec)
        end, last = drain(run_sequence(
            scene, spec.formulation, spec.solver, spec.estimator,
            spec.loop_config(max_memory_gib), run_columns(spec, run),
            truth=truth_of(scene), crosscheck_dofs=spec.crosscheck_dofs,
            formulation_options=dict(spec.formulation_options)), record_level)
        if last is not None:  # its fields are already written: copied, not computed again
            publish_last_level(out, last.row)
        return end
    except Exception as error:  # recorded, never silent: the row carries type and message
        if isinstance(error, OSError) and error.errno in FULL:
            raise  # the folder's fault, not the sequence's: the run stops, said once
        return failed_sequence(spec, names, record, error)


def failed_sequence(spec: SequenceSpec, names: dict, record, error: Exception) -> str:
    """A sequence that raised: one failed row with the error's type and message, and one
    line (bad input) or its traceback (a fault of the code)."""
    reason = f"{type(error).__name__}: {error}"
    record(whole_sequence_row(names, STATUS_FAILED, reason))
    if isinstance(error, ValueError):  # bad input (a SceneError...): its one line says it
        print(f"error: {spec.scene}/{spec.formulation}/{spec.solver}/{spec.estimator}/"
              f"{spec.strategy}: {reason} (a failed row records it)", file=sys.stderr)
    else:  # a fault of the code: its traceback is what finds it
        traceback.print_exception(error)
    return STATUS_FAILED


WARM_UP_LEVELS = 2  # a level and a refinement: every code path a sequence times
_warmed: set = set()  # the combinations this process has already run once


def warm_up(scene: Scene, spec: SequenceSpec) -> None:
    """Run the first WARM_UP_LEVELS levels of the combination once per process, untimed and
    unrecorded, so that one-off start-up costs (imports, first factorisations, caches) are not
    charged to whichever sequence happens to run first (docs/report.md, "Ties and the timing
    noise"). A failure here is left to the timed run, which records it."""
    key = (spec.formulation, spec.solver, spec.estimator, spec.order, spec.cell, scene.dim)
    if key in _warmed:
        return
    _warmed.add(key)
    loop = replace(spec.loop_config(), max_levels=WARM_UP_LEVELS, target_error=None)
    try:
        for _ in run_sequence(scene, spec.formulation, spec.solver, spec.estimator, loop, {},
                              formulation_options=dict(spec.formulation_options)):
            pass
    except Exception:  # noqa: BLE001 - the timed run meets it again and records it
        return


def whole_sequence_row(names: dict, status: str, reason: str) -> LevelResult:
    """One row (level -1) standing for a whole sequence that was skipped or crashed."""
    return LevelResult(ResultRow(level=-1, status=status, reason=reason, **names), None, None)

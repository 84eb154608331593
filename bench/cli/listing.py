"""``python -m bench list``: every registered unit with its origin, then what was left out
(plugins and scene files that failed to load, units marked broken)."""

from __future__ import annotations

from bench.hard import hard_case_descriptions
from bench.hard.registry import HARD_CASES
from bench.matrix.plugins import FAILURES
from bench.matrix.scene_files import FILE_FAILURES
from estimators import estimator_descriptions
from estimators.base import ESTIMATORS
from estimators.goals.base import GOAL_ESTIMATORS
from estimators.quantities.base import QUANTITIES
from formulations import formulation_descriptions, solver_descriptions
from formulations.cells import CELL_FAMILIES
from formulations.elasticity import order_descriptions
from formulations.registry import FORMULATIONS
from formulations.solvers.backends.base import REGISTRY as BACKENDS
from formulations.solvers.registry import SOLVERS, SYSTEM_SOLVERS
from scenes import scene_descriptions
from scenes.registry import BUILT_IN, SCENES, broken_units


def list_command(args) -> int:
    """Every registered unit with its origin (built-in, a scene file, a plugin), then any
    plugin that failed to load."""
    for title, items, origin in LISTINGS:
        print(f"{title}:")
        for name, text in items().items():
            print(f"  {name:16s} [{origin(name)}] {text}")
    for failure in FAILURES:
        print(f"plugin {failure.distribution!r} skipped (entry point {failure.name!r} in "
              f"{failure.group}): {failure.reason}")
    for broken in FILE_FAILURES.values():
        print(f"scene file {broken.name!r} broken, left out: {broken.reason}")
    for kind, broken in broken_units():
        if broken.origin not in {f"file {f.name}" for f in FILE_FAILURES.values()}:
            print(f"{kind} {broken.name!r} broken, left out ({broken.origin}): {broken.reason}")
    return 0


def _solver_origin(name: str) -> str:
    return (SOLVERS if name in SOLVERS.names() else SYSTEM_SOLVERS).origin(name)


def _hard_origin(name: str) -> str:
    return (HARD_CASES if name in HARD_CASES.names() else SCENES).origin(name)


LISTINGS = (("scenes", scene_descriptions, SCENES.origin),
            ("formulations", formulation_descriptions, FORMULATIONS.origin),
            ("solvers", solver_descriptions, _solver_origin),
            ("sparse back-ends (--backend)", BACKENDS.descriptions, BACKENDS.origin),
            ("estimators", estimator_descriptions, ESTIMATORS.origin),
            ("quantities of interest (--goal)", QUANTITIES.descriptions, QUANTITIES.origin),
            ("goal estimators", GOAL_ESTIMATORS.descriptions, GOAL_ESTIMATORS.origin),
            ("orders (--order)", order_descriptions, lambda name: BUILT_IN),
            ("cell families (--cell tri: simplices, quad: tensor-product cells)",
             CELL_FAMILIES.descriptions, CELL_FAMILIES.origin),
            ("hard cases", hard_case_descriptions, _hard_origin))

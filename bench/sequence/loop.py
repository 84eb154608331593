"""The refinement loop solve -> estimate -> mark -> refine, one result row per level
(docs/theory.md, section 7)."""

from __future__ import annotations

import functools
import time
from collections.abc import Generator
from dataclasses import dataclass, field, fields

from skfem import MeshTri

from bench.sequence.columns import level_columns, solver_columns
from bench.sequence.components import (
    Previous,
    check_stopping_cell,
    check_stopping_settings,
    level_stopping,
)
from bench.sequence.goal import GOAL_STRATEGY
from bench.sequence.judged import judge_level
from bench.sequence.marking import MARKINGS, check_marking, mark
from bench.sequence.memory import (
    MemoryRoute,
    dense_block_route,
    level_memory,
    level_refusal,
)
from bench.sequence.nested import initial_displacement
from bench.sequence.options import option
from bench.sequence.rows import ResultRow, identity_columns
from estimators.base import estimator_on
from estimators.quantities import quantity_names
from formulations import STATUS_FAILED, get_formulation, solve
from formulations.cells import DEFAULT_CELL, check_cell, family_for
from formulations.cells.base import Plan
from formulations.discretisation import dense_block_size, takes_initial
from formulations.elasticity import check_order
from formulations.solvers.backends import backend_names, check_backend, iterative
from formulations.solvers.registry import REFERENCE_SOLVER
from formulations.solvers.stopping import GAMMA_ALG, GAMMA_LIN, STOPPING_RULES
from scenes import Scene
from scenes.base import is_integer, is_number

STRATEGIES = ("uniform", "adaptive", GOAL_STRATEGY)  # goal: marked by the goal's indicators


@dataclass(frozen=True)
class LoopSettings:
    """How every sequence of a run is run: the loop's settings that are also options of the
    command line and keys of a run file (``bench.sequence.options``); validated on
    construction."""

    max_dofs: int = option(20000, "DOF budget: stop before a level with more unknowns",
                           flag="max-dofs", kind="int>0", section="how")
    max_levels: int = option(40, "maximum number of levels", flag="max-levels", kind="int>0",
                             section="how")
    goal: str | None = option(
        None, "a quantity of interest (docs/theory.md, 20): every row gets its value, true "
        "error and dual-weighted estimate (the qoi columns), and the strategy goal refines by "
        "its dual-weighted indicators", flag="goal", kind="choice", section="what",
        choices=quantity_names, metavar="NAME",
        default_text="none (the strategy goal alone: contact-force)")
    target_error: float | None = option(
        None, "stop each sequence at the first level whose guaranteed error bound is at most "
        "TOL (energy norm; needs a guaranteed estimator such as equilibrated)",
        flag="target-error", kind="float>0", section="how", metavar="TOL", default_text="off")
    marking: str = option("doerfler", "adaptive marking: doerfler (bulk) or maximum",
                          flag="marking", kind="choice", section="how",
                          choices=lambda: list(MARKINGS))
    theta: float = option(0.5, "marking parameter in (0, 1]", flag="theta", kind="theta",
                          section="how")
    backend: str | None = option(
        None, "sparse back-end of the active-set solver: pardiso (MKL, installed with the "
        "package on x86_64), cholmod (needs scikit-sparse), splu (scipy) or amg (PyAMG's "
        "multigrid with conjugate gradients, no factorisation)",
        flag="backend", kind="choice", section="how", choices=backend_names,
        default_text="the first of pardiso, cholmod, splu that is available")
    stopping: str = option(
        "fixed", "when the solvers stop: fixed (their own tolerances) or adaptive (when the "
        "algebraic and linearisation error components fall below gamma-alg and gamma-lin "
        "times the discretisation's; docs/theory.md, 18.3)", flag="stopping", kind="choice",
        section="how", choices=lambda: list(STOPPING_RULES.names()))
    gamma_alg: float = option(GAMMA_ALG, "adaptive stopping: the Krylov solve stops when "
                              "eta_alg <= GAMMA (eta_disc + eta_lin), GAMMA in (0, 1)",
                              flag="gamma-alg", kind="float>0", section="how",
                              metavar="GAMMA")
    gamma_lin: float = option(GAMMA_LIN, "adaptive stopping: the active-set (Newton) "
                              "iteration stops when eta_lin <= GAMMA eta_disc, GAMMA in (0, 1)",
                              flag="gamma-lin", kind="float>0", section="how",
                              metavar="GAMMA")
    nested: bool = option(
        True, "solve every level from scratch instead of starting from the previous level's "
        "contact zone (nested iteration, the default)", flag="cold-start", kind="switch-off",
        section="how")
    # refuse a level whose predicted peak memory exceeds this (GiB); None: what the machine has
    # available minus a margin (bench.sequence.memory)
    max_memory_gib: float | None = option(
        None, "refuse (status failed) a level whose predicted peak memory exceeds this many "
        "GiB, before building it; a level only a factorisation would not fit is solved by "
        "an iterative back-end (amg) instead", flag="max-memory", kind="gib", section="where",
        metavar="GIB", default_text="the memory the machine has available, minus 10 % and "
        "at least 1 GiB")

    def __post_init__(self):
        for name in ("max_dofs", "max_levels"):
            value = getattr(self, name)
            if not (is_integer(value) and value > 0):
                raise ValueError(f"{name}={value!r} is not a positive integer")
        check_marking(self.marking, self.theta)
        if self.target_error is not None and not (
                is_number(self.target_error) and self.target_error > 0):
            raise ValueError(f"target_error={self.target_error!r} is not a number > 0")
        if self.max_memory_gib is not None and not (
                is_number(self.max_memory_gib) and self.max_memory_gib > 0):
            raise ValueError(f"max_memory_gib={self.max_memory_gib!r} is not a number > 0")
        if self.backend is not None:
            check_backend(self.backend)
        check_stopping_settings(self.stopping, self.gamma_alg, self.gamma_lin)
        if self.goal is not None and self.goal not in quantity_names():
            raise ValueError(f"goal={self.goal!r} is not one of {', '.join(quantity_names())}")

    def settings(self) -> dict:
        """The values of ``LoopSettings``' own fields (what a ``LoopConfig`` inherits)."""
        return {f.name: getattr(self, f.name) for f in fields(LoopSettings)}


@dataclass(frozen=True)
class LoopConfig(LoopSettings):
    """How one refinement sequence is run: the run's ``LoopSettings`` and the sequence's own
    strategy, order and cell; validated on construction."""

    strategy: str = "adaptive"
    order: int = 1  # polynomial order p of the displacements (formulations.elasticity.ORDERS)
    cell: str = DEFAULT_CELL  # the cell family's shape (formulations.cells): tri or quad
    grade_contact: bool = True  # 2:1 grading closure along Gamma_C (bench.sequence.marking)
    # the inf-sup constant: free with the active-set solver on cholmod (its condensed system),
    # else a factorisation and m solves per level
    diagnostics: bool = True
    solver_options: dict = field(default_factory=dict)  # more keywords of the solver

    def __post_init__(self):
        super().__post_init__()
        if self.strategy not in STRATEGIES:
            raise ValueError(f"strategy={self.strategy!r} is not one of {', '.join(STRATEGIES)}")
        check_order(self.order)
        check_cell(self.cell)
        check_stopping_cell(self.stopping, self.cell)

    def options(self) -> dict:
        """The solver's keywords: ``solver_options`` and the back-end."""
        return {**({"backend": self.backend} if self.backend else {}), **self.solver_options}


@dataclass(frozen=True, eq=False)
class LevelResult:
    """Everything one level produced: the row and the objects behind it (for plots, tests)."""

    row: ResultRow
    solution: object | None
    estimate: object | None


def refinement(mesh: MeshTri, sol, est, config: LoopConfig, indicators=None) -> Plan:
    """The plan of the next mesh: uniform refinement, or marking by ``indicators`` (default:
    the estimate's) plus the contact grading closure."""
    family = family_for(config.cell, mesh.dim())
    if config.strategy == "uniform":
        return family.refinement(mesh)
    marked = mark(est.indicators if indicators is None else indicators, config.marking,
                  config.theta)
    if config.grade_contact:  # a 2:1 grading along Gamma_C, where it has an order
        marked = sol.trace.graded(marked, mesh.t.shape[1])
    return family.refinement(mesh, marked)


def refine(mesh: MeshTri, sol, est, config: LoopConfig) -> MeshTri:
    """The next mesh (``refinement``'s plan carried out)."""
    return refinement(mesh, sol, est, config).refined


def level_options(level: int, disc, solver: str, config: LoopConfig, route: MemoryRoute,
                  previous) -> tuple[dict, MemoryRoute]:
    """The solve's options on the level's ``route``, moved to an iterative back-end if the
    assembled level's dense Schur block does not fit (``dense_block_route``), with the
    ``previous`` level's solution as warm start (nested iteration)."""
    options = config.options()
    backend = check_backend(options.get("backend"))
    route = dense_block_route(route, level, disc.ndofs, dense_block_size(disc, solver, backend),
                              solver, backend, config.order, disc.elasticity.mesh.dim())
    if route.backend is not None:
        options["backend"] = route.backend
    if config.nested and previous is not None and previous.ok:
        options["warm_start"] = disc.warm_start(previous, solver)
        if iterative(options.get("backend")) and takes_initial(disc, solver):
            initial = initial_displacement(previous, disc)
            if initial is not None:
                options["initial"] = initial
    return options, route


def refused(ident: dict, level: int, ndofs: int, mesh, refusal: tuple[str, str]):
    """Yield the failed row of a refused level (none for a later level merely over the
    budget: that is just the end); return the end reason."""
    end, reason = refusal
    if reason:
        yield refused_row(ident, level, ndofs, mesh, reason)
    return end


def timed(function, *args):
    """(function(*args), its wall time in s)."""
    start = time.perf_counter()
    return function(*args), time.perf_counter() - start


def refused_row(ident: dict, level: int, ndofs: int, mesh, reason: str) -> LevelResult:
    """The failed row of a level that is not built."""
    return LevelResult(ResultRow(**ident, level=level, ndofs=ndofs, n_elements=mesh.t.shape[1],
                                 status=STATUS_FAILED, reason=reason), None, None)


def run_sequence(scene: Scene, formulation: str, solver: str, estimator: str,
                 config: LoopConfig, identity: dict | None = None,
                 mesh: MeshTri | None = None, truth=None, crosscheck_dofs: int = 0,
                 formulation_options: dict | None = None) -> Generator[LevelResult, None, str]:
    """Yield one ``LevelResult`` per level until the DOF budget or the level count is reached,
    or a level fails (its row says why); return why it ended (``budget``, ``max_levels``,
    ``memory``, ``failed``, ``target``). ``truth`` (``bench.truth``): errors and effectivity
    per level; ``identity``: the run's columns; ``formulation_options``: to ``discretise``."""
    discretise = functools.partial(get_formulation(formulation), order=config.order,
                                   **(formulation_options or {}))
    family = family_for(config.cell, scene.dim)
    estimate = estimator_on(estimator, family.name)
    ident = identity_columns(scene.name, formulation, solver, estimator, config, identity,
                             scene.dim)
    mesh = family.starting_mesh(scene) if mesh is None else mesh
    t_refine, previous, predicted = 0.0, None, None
    for level in range(config.max_levels):
        ndofs = family.count_free_dofs(scene, mesh, config.order)  # before any assembly
        # decided once, before the assembly: the prediction includes the assembly's memory,
        # and asked again after it, a level admitted on an iterative back-end could be
        # refused there and fall back to the configured direct one
        route = level_memory(level, ndofs, solver, config, scene.dim)
        refusal = level_refusal(level, ndofs, config, route)
        if refusal is not None:  # over the budget or the memory: a failed row says so
            return (yield from refused(ident, level, ndofs, mesh, refusal))
        scene.check_mesh(mesh, level)
        start = time.perf_counter()
        disc = discretise(scene, mesh)
        t_assemble = time.perf_counter() - start
        options, route = level_options(level, disc, solver, config, route, previous)
        stopping = level_stopping(scene, disc, config, estimator, predicted)
        sol = previous = solve(disc, solver, stopping=stopping, **options)
        failed = sol.status == STATUS_FAILED
        est, t_estimate = (None, float("nan")) if failed else timed(estimate, scene, sol)
        numbers = dict(level_columns(disc, sol, mesh, options), level=level,
                       t_assemble=t_assemble, t_refine=t_refine, t_estimate=t_estimate,
                       **(solver_columns(sol.diagnostics) if failed else {}))
        judged = None if failed else judge_level(scene, disc, sol, est, config, options, truth,
                                                 solver != REFERENCE_SOLVER
                                                 and disc.ndofs <= crosscheck_dofs)
        if judged is not None:
            numbers.update(judged.numbers)
            predicted = Previous(numbers["eta_disc"], disc.ndofs)
        reached = None if failed else judged.reached
        numbers["reason"] = "; ".join(filter(None, (numbers["reason"], route.note,
                                                    judged and judged.note, reached)))
        yield LevelResult(ResultRow(**ident, **numbers), sol, est)
        if failed:
            return "failed"
        if reached:
            return "target"
        start = time.perf_counter()
        plan = refinement(mesh, sol, est, config, judged.indicators)
        # the next level's size before its triangles are made: no refinement is wasted
        if plan.free_dofs(scene, config.order) > config.max_dofs:
            return "budget"
        mesh = plan.refined
        t_refine = time.perf_counter() - start
    return "max_levels"

"""The refinement loop solve -> estimate -> mark -> refine, one result row per level."""

from __future__ import annotations

import time
from collections.abc import Iterator
from dataclasses import dataclass, field

from skfem import MeshTri

from bench.errors import TOO_COARSE, solution_difference
from bench.marking import MARKINGS, grade_contact_trace, mark
from bench.rows import ResultRow
from estimators import get_estimator
from formulations import STATUS_FAILED, get_formulation, solve
from formulations.diagnostics import inf_sup_constant, pressure_oscillation
from formulations.elasticity import element_diameters
from scenes import Scene

STRATEGIES = ("uniform", "adaptive")


@dataclass(frozen=True)
class LoopConfig:
    """How a refinement sequence is run; validated on construction."""

    strategy: str = "adaptive"
    max_dofs: int = 20000
    max_levels: int = 40
    marking: str = "doerfler"
    theta: float = 0.5
    nested: bool = True
    grade_contact: bool = True  # 2:1 grading closure along Gamma_C (bench.marking)
    # the inf-sup constant: free with the active-set solver on cholmod (its condensed system),
    # else a factorisation and m solves per level
    diagnostics: bool = True
    solver_options: dict = field(default_factory=dict)

    def __post_init__(self):
        if self.strategy not in STRATEGIES:
            raise ValueError(f"strategy={self.strategy!r} is not one of {', '.join(STRATEGIES)}")
        if not (isinstance(self.max_dofs, int) and self.max_dofs > 0):
            raise ValueError(f"max_dofs={self.max_dofs!r} is not a positive integer")
        if not (isinstance(self.max_levels, int) and self.max_levels > 0):
            raise ValueError(f"max_levels={self.max_levels!r} is not a positive integer")
        if self.marking not in MARKINGS:
            raise ValueError(f"marking={self.marking!r} is not one of {', '.join(MARKINGS)}")
        if not 0.0 < self.theta <= 1.0:
            raise ValueError(f"theta={self.theta!r} is not in (0, 1]")


@dataclass(frozen=True, eq=False)
class LevelResult:
    """Everything one level produced: the row and the objects behind it (for plots, tests)."""

    row: ResultRow
    solution: object | None
    estimate: object | None


def error_columns(truth, solution, estimate) -> dict:
    """Errors against ``truth`` (``bench.truth``) and effectivity indices eta / error."""
    start = time.perf_counter()
    errors = truth.errors(solution)
    out = dict(vars(errors), truth=truth.kind, reference_error=truth.estimated_error,
               reference_too_coarse=bool(truth.estimated_error > TOO_COARSE *
                                         errors.energy_error))
    if estimate is not None and errors.energy_error > 0:
        out.update(effectivity_index=estimate.eta / errors.energy_error,
                   effectivity_0=estimate.eta_0 / errors.energy_error,
                   effectivity_geometric=estimate.eta_geometric / errors.energy_error,
                   effectivity_complementarity=estimate.eta_complementarity
                   / errors.energy_error)
    out["t_error"] = time.perf_counter() - start
    return out


def diagnostic_columns(disc, sol, config: LoopConfig) -> dict:
    """The solver's diagnostics and the stability measures of ``formulations.diagnostics``."""
    start = time.perf_counter()
    diag = sol.diagnostics
    out = dict(condition_estimate=diag.get("condition_estimate", float("nan")),
               active_set_changes=",".join(map(str, diag.get("active_set_changes", ()))),
               cycled=bool(diag.get("cycled", False)), safeguard=diag.get("safeguard", ""),
               pressure_oscillation=pressure_oscillation(sol))
    if config.diagnostics:
        out["inf_sup"] = inf_sup_constant(disc, config.solver_options.get("backend"),
                                          condensed=diag.get("condensed"))
    out["t_diagnostics"] = time.perf_counter() - start
    return out


def crosscheck_columns(disc, sol) -> dict:
    """Solve the same discrete problem with the reference solver and compare: relative
    energy-norm difference of u_h and max pressure difference relative to max lambda_h."""
    judge = solve(disc, "reference")
    out = {"crosscheck_status": judge.status}
    if judge.status == STATUS_FAILED:
        return out
    energy, pressure = solution_difference(disc, sol, judge)
    out.update(crosscheck_energy_difference=energy, crosscheck_pressure_difference=pressure)
    return out


def run_sequence(scene: Scene, formulation: str, solver: str, estimator: str,
                 config: LoopConfig, identity: dict | None = None,
                 mesh: MeshTri | None = None, truth=None,
                 crosscheck_dofs: int = 0) -> Iterator[LevelResult]:
    """Yield one ``LevelResult`` per level until the DOF budget or the level count is reached,
    or a level fails (its row says why). With a ``truth`` (``bench.truth``) every level also
    gets its errors and effectivity indices."""
    discretise, estimate = get_formulation(formulation), get_estimator(estimator)
    ident = dict(scene=scene.name, formulation=formulation, solver=solver, estimator=estimator,
                 strategy=config.strategy, marking=config.marking, theta=config.theta,
                 **(identity or {}))
    mesh = scene.mesh if mesh is None else mesh
    t_refine, previous = 0.0, None
    for level in range(config.max_levels):
        start = time.perf_counter()
        disc = discretise(scene, mesh)
        t_assemble = time.perf_counter() - start
        if level > 0 and disc.ndofs > config.max_dofs:
            return
        options = dict(config.solver_options)
        if config.nested and previous is not None and previous.ok:
            options["warm_start"] = disc.warm_start(previous)  # nested iteration
        sol = solve(disc, solver, **options)
        previous = sol
        start = time.perf_counter()
        est = estimate(scene, sol) if sol.status != STATUS_FAILED else None
        t_estimate = time.perf_counter() - start if est is not None else float("nan")
        h = element_diameters(mesh)
        numbers = dict(
            level=level, ndofs=disc.ndofs, n_elements=mesh.t.shape[1], h_max=float(h.max()),
            h_min=float(h.min()), max_h_over_H=sol.max_h_over_H, energy=sol.energy,
            contact_force=sol.contact_force(), active_constraints=sol.active_constraints,
            n_constraints=disc.qp.m, iterations=sol.iterations, backend=sol.backend,
            warm_started="warm_start" in options, t_assemble=t_assemble,
            t_solve=sol.solve_time, t_estimate=t_estimate, t_refine=t_refine,
            status=sol.status, reason=sol.reason, **vars(sol.residuals))
        if sol.status != STATUS_FAILED:
            numbers.update(diagnostic_columns(disc, sol, config))
        else:
            numbers.update(cycled=bool(sol.diagnostics.get("cycled", False)),
                           safeguard=sol.diagnostics.get("safeguard", ""))
        if est is not None:
            numbers.update(eta=est.eta, eta_0=est.eta_0, eta_geometric=est.eta_geometric,
                           eta_complementarity=est.eta_complementarity)
        if truth is not None and sol.status != STATUS_FAILED:
            numbers.update(error_columns(truth, sol, est))
        if solver != "reference" and disc.ndofs <= crosscheck_dofs and sol.status != STATUS_FAILED:
            numbers.update(crosscheck_columns(disc, sol))
        yield LevelResult(ResultRow(**ident, **numbers), sol, est)
        if sol.status == STATUS_FAILED:
            return
        start = time.perf_counter()
        if config.strategy == "uniform":
            refined = mesh.refined()
        else:
            marked = mark(est.indicators, config.marking, config.theta)
            if config.grade_contact:
                trace = sol.trace
                marked = grade_contact_trace(marked, trace.length, trace.element,
                                             trace.coordinate, mesh.t.shape[1])
            refined = mesh.refined(marked)
        t_refine = time.perf_counter() - start
        mesh = refined


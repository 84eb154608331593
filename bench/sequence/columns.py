"""The column groups of a level's result row beyond its basic numbers: errors against the
truth, the solver's and the discretisation's stability diagnostics, and the cross-check by the
reference solver (docs/theory.md, section 7)."""

from __future__ import annotations

import math
import time

from bench.measure.contact import STATUS_UNRESOLVED, contact_resolution, zone_error
from bench.measure.difference import solution_difference
from bench.measure.discretisation_error import shear_error
from bench.sequence.components import component_columns
from formulations import STATUS_FAILED, STATUS_OK, STATUS_SKIPPED, SolverDiagnostics, solve
from formulations.diagnostics import inf_sup_constant, pressure_oscillation
from formulations.discretisation import why_unsolvable
from formulations.elasticity import element_diameters
from formulations.solvers.registry import REFERENCE_SOLVER


def error_columns(truth, solution, estimate) -> dict:
    """Errors against ``truth`` (``bench.truth``) and effectivity indices eta / error."""
    start = time.perf_counter()
    errors = truth.errors(solution)
    out = dict(vars(errors), truth=truth.kind, reference_error=truth.estimated_error,
               reference_too_coarse=truth.too_coarse(errors.energy_error, solution))
    if estimate is not None and errors.energy_error > 0:
        out.update(effectivity_index=estimate.eta / errors.energy_error,
                   effectivity_0=estimate.eta_0 / errors.energy_error,
                   effectivity_geometric=estimate.eta_geometric / errors.energy_error,
                   effectivity_complementarity=estimate.eta_complementarity
                   / errors.energy_error)
    out["t_error"] = time.perf_counter() - start
    return out


def total_effectivity(numbers: dict) -> dict:
    """eta_total / error of a level's columns (NaN without both)."""
    error, total = numbers.get("energy_error", math.nan), numbers.get("eta_total", math.nan)
    return {"effectivity_total": total / error if error > 0 else math.nan}


def friction_columns(scene, solution) -> dict:
    """The friction law and its answer (docs/columns.md): points that stick and slip, the
    stick zone and, against an exact solution that has them, its error and the shear
    traction's."""
    out = {"friction": scene.friction.label}
    state = solution.friction
    if state is None:
        return out
    zone = state.zone("stick")
    out.update(stick_points=int((state.state == "stick").sum()),
               slip_points=int((state.state == "slip").sum()),
               stick_zone_start=zone[0], stick_zone_end=zone[1])
    exact = scene.exact
    if exact is not None and exact.stick_zone is not None:
        out.update(stick_zone_error=zone_error(zone, exact.stick_zone),
                   shear_error=shear_error(solution, exact.shear))
    return out


def solver_columns(diagnostics: SolverDiagnostics) -> dict:
    """The solver's own diagnostics as result columns."""
    return dict(condition_estimate=diagnostics.condition_estimate,
                active_set_changes=",".join(map(str, diagnostics.active_set_changes)),
                cycled=diagnostics.cycled, safeguard=diagnostics.safeguard)


def diagnostic_columns(disc, sol, inf_sup: bool, backend: str | None) -> dict:
    """The solver's diagnostics and the stability measures of ``formulations.diagnostics``;
    ``inf_sup``: compute the inf-sup constant too (free when the solver kept B K^-1 B')."""
    start = time.perf_counter()
    out = dict(solver_columns(sol.diagnostics), pressure_oscillation=pressure_oscillation(sol))
    if inf_sup:
        out["inf_sup"] = inf_sup_constant(disc, backend, condensed=sol.diagnostics.condensed)
    out["t_diagnostics"] = time.perf_counter() - start
    return out


def crosscheck_columns(disc, sol) -> dict:
    """Solve the same discrete problem with the reference solver and compare: relative
    energy-norm difference of u_h and max pressure difference relative to max lambda_h."""
    why = why_unsolvable(disc, REFERENCE_SOLVER)
    if why is not None:  # no form the reference can solve (a nonsymmetric Nitsche variant)
        return {"crosscheck_status": STATUS_SKIPPED}
    reference = solve(disc, REFERENCE_SOLVER)
    out = {"crosscheck_status": reference.status}
    if reference.status == STATUS_FAILED:
        return out
    energy, pressure = solution_difference(disc, sol, reference)
    out.update(crosscheck_energy_difference=energy, crosscheck_pressure_difference=pressure)
    return out


def level_columns(disc, sol, mesh, options: dict) -> dict:
    """The basic numbers of a solved level: sizes, energy, contact, residuals, status."""
    h = element_diameters(mesh)
    return dict(
        ndofs=disc.ndofs, n_elements=mesh.t.shape[1], h_max=float(h.max()),
        h_min=float(h.min()), max_h_over_H=sol.max_h_over_H, energy=sol.energy,
        contact_force=sol.contact_force(), active_constraints=sol.active_constraints,
        n_constraints=disc.n_constraints, iterations=sol.iterations, backend=sol.backend,
        warm_started="warm_start" in options, t_solve=sol.solve_time, status=sol.status,
        reason=sol.reason, **vars(sol.residuals))

def resolution_columns(scene, sol) -> dict:
    """The penetration columns of a solved level and, when the discrete constraint did not see
    the contact, the status ``contact unresolved`` with the reason (never a plain ok)."""
    resolution = contact_resolution(scene, sol)
    out = resolution.columns()
    if resolution.unresolved and sol.status == STATUS_OK:
        out.update(status=STATUS_UNRESOLVED, reason="; ".join(filter(None, (
            sol.reason, resolution.unresolved))))
    return out


def solved_columns(scene, disc, sol, est, config, options: dict, truth,
                   crosscheck: bool) -> dict:
    """The columns of a solved level beyond its basic numbers: diagnostics, friction, the
    estimate and its parts, the iterate's error components, the errors against ``truth``
    (if given) and the reference solver's cross-check (if ``crosscheck``)."""
    numbers = dict(diagnostic_columns(disc, sol, config.diagnostics, options.get("backend")),
                   **friction_columns(scene, sol),
                   eta=est.eta, eta_0=est.eta_0, eta_geometric=est.eta_geometric,
                   eta_complementarity=est.eta_complementarity,
                   **(est.bound.columns() if est.bound is not None else {}),
                   **component_columns(sol, est), **resolution_columns(scene, sol))
    if truth is not None:
        numbers.update(error_columns(truth, sol, est))
        numbers.update(total_effectivity(numbers))
    if crosscheck:
        numbers.update(crosscheck_columns(disc, sol))
    return numbers

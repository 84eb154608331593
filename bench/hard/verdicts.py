"""Verdicts of the hard cases (docs/theory.md, section 8): each (hard case x formulation
x solver x variant) row gets a loss, a pressure loss and a verdict.

Every discrete problem is solved by every registered solver. The **loss** of a row is how far
it is from the exact discrete solution: the larger of its own KKT residuals
(``formulations.kkt``) and its relative energy-norm difference to the best-certified answer
(the one with the smallest residuals and penalty self-check; for a convex QP, residuals at
round-off certify the minimiser); its
**pressure loss** is the max pressure difference to that answer, relative to max lambda_h. The
pressure counts because a penalty pressure (u_hn - g_h)_+ / eps magnifies an error in u by
1/eps: an answer can be right in energy and wrong in pressure. Verdicts:

* ``accurate``: converged, loss <= ``LOSS_TOLERANCE`` and pressure loss <=
  ``PRESSURE_TOLERANCE``;
* ``inaccurate``: converged (status ok or inaccurate) but above either bar -- the loss columns
  give the measured loss;
* ``contact unresolved``: converged, but the discrete constraint did not see the contact (the
  penetration undoes more than a tenth of the obstacle's approach, or nothing is active where
  the obstacle is pushed in: ``bench.measure.contact``), whatever the loss;
* ``failed``: no solution; the reason says why;
* ``refused``: an invalid problem, rejected with a clear error before any solve.

``finding`` states what the case is about, measured (inf-sup decay, penetration, scaling...).
The expected verdicts live in ``bench/verify/expected.toml`` ([[hard]]), checked by
``python -m bench hard``, ``python -m bench verify`` and tests/bench/hard. The cases are in
``bench.hard.cases``.
"""

from __future__ import annotations

import numpy as np

from bench.measure.contact import STATUS_UNRESOLVED, contact_resolution
from bench.measure.difference import solution_difference
from formulations import STATUS_FAILED, STATUS_OK, get_formulation, solve, solver_names
from formulations.diagnostics import inf_sup_constant, pressure_oscillation
from formulations.discretisation import why_unsolvable
from scenes import Scene

LOSS_TOLERANCE = 1e-6  # the same bar as a residual for status "ok" (formulations.kkt)
# the pressure is a pointwise, derived quantity: the reference (tolerances 1e-10) gets the mixed
# multipliers to ~1e-8, but the penalty pressure only to 1e-5..4e-4 at the default eps_0 = 1e-3
# (measured), which is still a usable answer; 0.1 % (as the penalty's own self-check,
# formulations.methods.penalty.PRESSURE_CONSISTENCY) separates that from a wrong pressure
PRESSURE_TOLERANCE = 1e-3
ACCURATE, INACCURATE, FAILED, REFUSED = "accurate", "inaccurate", "failed", "refused"
UNRESOLVED = STATUS_UNRESOLVED


def _record(case, scene, formulation, disc, sol, variant, level) -> dict:
    residual = max(vars(sol.residuals).values())
    solved = sol.status != STATUS_FAILED
    resolution = contact_resolution(scene, sol) if solved else None
    return dict(case=case, scene=scene.name, formulation=formulation, solver=sol.solver,
                variant=variant, level=level, ndofs=disc.ndofs, status=sol.status,
                reason=sol.reason, backend=sol.backend,
                safeguard=sol.diagnostics.safeguard,
                iterations=sol.iterations, max_residual=residual,
                condition_estimate=sol.diagnostics.condition_estimate,
                inf_sup=np.nan, pressure_oscillation=pressure_oscillation(sol),
                contact_force=sol.contact_force() if sol.status != STATUS_FAILED else np.nan,
                active_constraints=sol.active_constraints, n_constraints=disc.n_constraints,
                penetration=resolution.penetration if solved else np.nan,
                nodal_penetration=resolution.nodal_penetration if solved else np.nan,
                penetration_share=resolution.penetration_share if solved else np.nan,
                unresolved=resolution.unresolved if solved else "", finding="")


def _certificate(record: dict, sol) -> float:
    """How far an answer shows itself from the exact discrete solution: its residuals, and the
    penalty's pressure self-check (an interior-point answer can have small KKT residuals and a
    pressure wrong by 1 %: it must not become the answer the others are judged against)."""
    value = max(record["max_residual"], sol.pressure_mismatch)
    return value if np.isfinite(value) else np.inf


def verdict(status: str, loss: float, pressure_loss: float = 0.0, unresolved: str = "") -> str:
    if status == STATUS_FAILED or not np.isfinite(loss):
        return FAILED
    if unresolved:
        return UNRESOLVED
    accurate = loss <= LOSS_TOLERANCE and pressure_loss <= PRESSURE_TOLERANCE
    return ACCURATE if status == STATUS_OK and accurate else INACCURATE


def solve_both(case: str, scene: Scene, formulation: str, mesh, variant: str = "",
               level: int = 0, inf_sup: bool = False, **options) -> tuple[list[dict], list]:
    """Every solver that has a method for the discrete problem: records with loss and
    verdict, and the solutions (in the order of ``solver_names()``)."""
    disc = get_formulation(formulation)(scene, mesh, **options)
    solutions = [solve(disc, solver) for solver in solver_names()
                 if why_unsolvable(disc, solver) is None]
    records = [_record(case, scene, formulation, disc, sol, variant, level)
               for sol in solutions]
    best = int(np.argmin([_certificate(r, sol) for r, sol in zip(records, solutions,
                                                                    strict=True)]))
    # B K^-1 B' from whichever solver formed it (the active-set solver on pardiso or cholmod)
    condensed = next((s.diagnostics.condensed for s in solutions
                      if s.diagnostics.condensed is not None), None)
    beta = inf_sup_constant(disc, condensed=condensed) if inf_sup else np.nan
    for record, sol in zip(records, solutions, strict=True):
        differences = (0.0, 0.0)
        if sol is not solutions[best] and sol.status != STATUS_FAILED:
            differences = solution_difference(disc, sol, solutions[best])
        # the penalty's own pressure self-check is a measured pressure loss too
        record.update(loss=max(record["max_residual"], differences[0]),
                      pressure_loss=max(differences[1], sol.pressure_mismatch), inf_sup=beta)
        record["verdict"] = verdict(record["status"], record["loss"], record["pressure_loss"],
                                    record["unresolved"])
    return records, solutions

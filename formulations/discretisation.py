"""A formulation's discrete problem on one mesh and the generic solve step."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from formulations.base import STATUS_FAILED, ContactQP, DiscreteSolution, QPSolution, Residuals
from formulations.contact import ContactTrace
from formulations.elasticity import Elasticity
from formulations.kkt import final_status, qp_residuals
from formulations.solvers import get_solver


@dataclass(frozen=True, eq=False)
class Discretisation:
    """What a formulation's ``discretise`` returns: the assembled QP on the free DOFs and how to
    turn a solver's answer into a ``DiscreteSolution`` (``recover(qp_solution, residuals,
    status, reason)``). ``row_coordinate`` places each constraint row on Gamma_C (the scene's
    contact coordinate of its segment's middle or its node). ``multiplier_gram`` (optional)
    makes the discrete inf-sup constant computable."""

    formulation: str
    elasticity: Elasticity
    trace: ContactTrace
    qp: ContactQP
    recover: Callable[[QPSolution, Residuals, str, str], DiscreteSolution]
    row_coordinate: np.ndarray
    transfer: Callable[[DiscreteSolution], np.ndarray] | None = None
    # Gram matrix (its diagonal if 1-D) of the mesh-dependent H^-1/2 norm of the multipliers, for
    # formulations whose constraint rows are a multiplier space (formulations.diagnostics)
    multiplier_gram: np.ndarray | None = None

    def warm_start(self, previous: DiscreteSolution) -> np.ndarray:
        """Initial multipliers for this QP from a solution on another (coarser) mesh: the
        previous lambda_h at each constraint row's place on Gamma_C (nested iteration), unless
        the formulation's rows need their own ``transfer``."""
        if self.transfer is not None:
            return self.transfer(previous)
        return previous.pressure_at(self.row_coordinate)

    @property
    def ndofs(self) -> int:
        return self.elasticity.ndofs


def discrete_solution(formulation: str, elasticity: Elasticity, trace: ContactTrace,
                      answer: QPSolution, residuals: Residuals, status: str, reason: str, *,
                      u_free: np.ndarray, pressure, multiplier_breaks: np.ndarray,
                      active_constraints: int, **specific) -> DiscreteSolution:
    """The common part of every formulation's ``recover``: a solver's answer plus the
    formulation's own u_h (free DOFs), lambda_h and contact mesh."""
    return DiscreteSolution(
        formulation=formulation, solver=answer.solver, elasticity=elasticity, trace=trace,
        u=elasticity.expand(u_free), pressure=pressure, multiplier_breaks=multiplier_breaks,
        residuals=residuals, status=status, reason=reason, iterations=answer.iterations,
        solve_time=answer.solve_time, active_constraints=active_constraints,
        backend=answer.backend, diagnostics=answer.diagnostics,
        multipliers=np.maximum(answer.multipliers, 0.0), **specific)


def solve(discretisation: Discretisation, solver: str, **options) -> DiscreteSolution:
    """Solve with the named solver, compute the KKT residuals from the returned arrays, and
    give the final status. A failed solve carries status ``failed`` and NaN arrays (never
    silently)."""
    answer = get_solver(solver)(discretisation.qp, **options)
    if answer.u is None or answer.multipliers is None:
        nan = np.full(discretisation.qp.n, np.nan)
        answer = QPSolution(nan, np.full(discretisation.qp.m, np.nan), answer.status or
                            STATUS_FAILED, answer.reason, answer.iterations, answer.solve_time,
                            answer.solver, answer.backend, answer.diagnostics)
        residuals = Residuals(*(4 * [float("nan")]))
        status, reason = final_status(answer, None)
    else:
        residuals = qp_residuals(discretisation.qp, answer.u, answer.multipliers)
        status, reason = final_status(answer, residuals)
    return discretisation.recover(answer, residuals, status, reason)

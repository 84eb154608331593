"""A formulation's discrete problem on one mesh and the generic solve step."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np
from scipy import sparse

from formulations.base import (
    STATUS_FAILED,
    ContactQP,
    DiscreteSolution,
    QPSolution,
    Residuals,
    slack_warm_start,
)
from formulations.contact.edges import ContactTrace
from formulations.elasticity import Elasticity
from formulations.kkt import final_status, qp_residuals
from formulations.semismooth import SemismoothSystem
from formulations.solvers.registry import SOLVERS, SYSTEM_SOLVERS
from formulations.solvers.stopping import (
    FIXED_STOPPING,
    Stopping,
    qp_components,
    stopped_status,
    system_components,
)


@dataclass(frozen=True, eq=False)
class Discretisation:
    """What a formulation's ``discretise`` returns: the assembled QP on the free DOFs (or None
    when the formulation has no QP form, ``no_qp`` saying why), optionally a
    ``SemismoothSystem`` (formulations.semismooth), and how to turn a solver's answer into a
    ``DiscreteSolution`` (``recover(qp_solution, residuals, status, reason)``; the answer's u
    and multipliers are those of the problem it solved).
    ``row_coordinate`` places each constraint row (or quadrature point of a system) on Gamma_C
    (the scene's contact coordinate). ``multiplier_gram`` (optional) makes the discrete inf-sup
    constant computable."""

    formulation: str
    elasticity: Elasticity
    trace: ContactTrace
    qp: ContactQP | None
    recover: Callable[[QPSolution, Residuals, str, str], DiscreteSolution]
    row_coordinate: np.ndarray
    transfer: Callable[[DiscreteSolution], np.ndarray] | None = None
    # Gram matrix (its diagonal if 1-D) of the mesh-dependent H^-1/2 norm of the multipliers, for
    # formulations whose constraint rows are a multiplier space (formulations.diagnostics)
    multiplier_gram: np.ndarray | sparse.spmatrix | None = None  # a vector is its diagonal
    system: SemismoothSystem | None = None
    no_qp: str = ""  # why qp is None
    # the QP is the system's slack form (formulations.base.slack_qp): per point of the system,
    # a row u_n - s <= g and a row s >= 0
    qp_is_slack_form: bool = False

    def warm_start(self, previous: DiscreteSolution, solver: str | None = None) -> np.ndarray:
        """Initial multipliers for the problem ``solver`` solves (the system if it has a method
        for it, else the QP) from a solution on another (coarser) mesh: the previous lambda_h
        at each constraint row's place on Gamma_C (nested iteration), unless the formulation's
        rows need their own ``transfer``; for a slack-form QP, which of each point's two rows
        is active."""
        values = (self.transfer(previous) if self.transfer is not None
                  else previous.pressure_at(self.row_coordinate))
        if self.qp_is_slack_form and solver is not None and not uses_system(self, solver):
            return slack_warm_start(values > 0)
        return values

    @property
    def ndofs(self) -> int:
        return self.elasticity.ndofs

    @property
    def n_constraints(self) -> int:
        """Quadrature points of the system, or constraint rows of the QP."""
        return self.system.nq if self.system is not None else self.qp.m

    @property
    def objective_scale(self) -> float:
        """Young's modulus, the scale of K."""
        return (self.qp or self.system).objective_scale

    @property
    def gap_scale(self) -> float:
        """The largest gap (a length; 0 if every gap is 0)."""
        if self.qp is not None:
            return self.qp.gap_scale
        return float(np.abs(self.system.gap).max(initial=0.0))


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


def uses_system(discretisation: Discretisation, solver: str) -> bool:
    """Whether ``solver`` solves the discretisation's semismooth system (else its QP)."""
    return discretisation.system is not None and solver in SYSTEM_SOLVERS.names()


def takes_initial(discretisation: Discretisation, solver: str) -> bool:
    """Whether ``solver`` starts from a given displacement (``initial``: nested iteration on
    an iterative back-end) for what the discretisation offers."""
    registry = SYSTEM_SOLVERS if uses_system(discretisation, solver) else SOLVERS
    return bool(registry.meta(solver, "initial"))


def why_unsolvable(discretisation: Discretisation, solver: str) -> str | None:
    """Why ``solver`` has no method for what the discretisation offers, or None."""
    if uses_system(discretisation, solver) or (discretisation.qp is not None
                                               and solver in SOLVERS.names()):
        return None
    if discretisation.qp is None:
        return (f"solver {solver!r} needs a QP and formulation "
                f"{discretisation.formulation!r} has none here: {discretisation.no_qp}")
    return f"solver {solver!r} has no method for a QP"


def dense_block_size(discretisation: Discretisation, solver: str, backend: str | None) -> int:
    """The columns of the dense Schur block ``solver`` would form on ``backend`` for this
    problem: what its registration declares (``meta["dense_block_size"](problem, backend)``),
    0 if it declares nothing (docs/theory.md, section 16, "Route choice")."""
    on_system = uses_system(discretisation, solver)
    registry = SYSTEM_SOLVERS if on_system else SOLVERS
    size = registry.meta(solver, "dense_block_size")
    problem = discretisation.system if on_system else discretisation.qp
    return 0 if size is None or problem is None else int(size(problem, backend))


def qp_safeguard(discretisation: Discretisation, solver: str, options: dict,
                 failed: QPSolution) -> tuple[QPSolution, SemismoothSystem | None]:
    """The formulation's QP solved by ``solver`` after its semismooth Newton iteration
    ``failed``: (the answer, None); where that method fails too (an indefinite K, say), the
    Newton failure with both reasons, and the system (the row is about the system)."""
    try:
        answer = SOLVERS.get(solver)(discretisation.qp, **{
            k: v for k, v in options.items() if k != "warm_start"})  # a system's start
    except Exception as error:  # noqa: BLE001 - said in the reason, the row stays failed
        return replace(failed, reason=f"{failed.reason}; the QP method failed too: "
                       f"{type(error).__name__}: {error}"), discretisation.system
    if answer.status == STATUS_FAILED:
        return replace(failed, reason=f"{failed.reason}; the QP method failed too: "
                       f"{answer.reason}"), discretisation.system
    return replace(answer, reason="; ".join(filter(None, (
        f"semismooth Newton failed ({failed.reason}); answered by {solver} on the "
        "formulation's QP (safeguard)", answer.reason))), diagnostics=replace(
        answer.diagnostics, safeguard=", then ".join(filter(None, (
            "the QP method", answer.diagnostics.safeguard))))), None


def solve(discretisation: Discretisation, solver: str, stopping: Stopping = FIXED_STOPPING,
          **options) -> DiscreteSolution:
    """Solve with the named solver, compute the residuals (KKT for a QP, the nonlinear
    residual for a system) from the returned arrays, and give the final status. A failed
    solve carries status ``failed`` and NaN arrays (never silently). A semismooth system whose
    Newton iteration fails is solved as the formulation's QP where it has one (the same
    problem; that method has its own safeguards, the reference solver last). ``stopping``
    goes to a solver that takes one (``meta["stopping"]``); the iterate's error components
    under it are measured here (``formulations.solvers.stopping``)."""
    why = why_unsolvable(discretisation, solver)
    if why is not None:
        raise ValueError(why)
    system = discretisation.system if uses_system(discretisation, solver) else None
    registry = SYSTEM_SOLVERS if system is not None else SOLVERS
    if registry.meta(solver, "stopping"):
        options["stopping"] = stopping
    answer = SYSTEM_SOLVERS.get(solver)(system, **options) if system is not None else None
    if answer is not None and answer.status == STATUS_FAILED \
            and discretisation.qp is not None and solver in SOLVERS.names():
        if not SOLVERS.meta(solver, "stopping"):
            options.pop("stopping", None)
        answer, system = qp_safeguard(discretisation, solver, options, answer)
    elif answer is None:
        answer = SOLVERS.get(solver)(discretisation.qp, **options)
    n, m = (system.n, system.nq) if system is not None else (discretisation.qp.n,
                                                            discretisation.qp.m)
    if answer.u is None or answer.multipliers is None:
        answer = QPSolution(np.full(n, np.nan), np.full(m, np.nan), answer.status or
                            STATUS_FAILED, answer.reason, answer.iterations, answer.solve_time,
                            answer.solver, answer.backend, answer.diagnostics)
        residuals = Residuals(*(4 * [float("nan")]))
        status, reason = final_status(answer, None)
    else:
        residuals = (system.residuals(answer.u) if system is not None else
                     qp_residuals(discretisation.qp, answer.u, answer.multipliers,
                                  answer.tangential))
        status, reason = final_status(answer, residuals)
    components = (system_components(system, answer, stopping) if system is not None
                  else qp_components(discretisation.qp, answer, stopping))
    status, reason = stopped_status(answer, components, stopping, status, reason)
    return replace(discretisation.recover(answer, residuals, status, reason),
                   components=components)

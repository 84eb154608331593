"""A contact QP on which the plain active-set iteration cycles: the safeguard answers."""

from __future__ import annotations

import numpy as np

from bench.hard.registry import hard_case
from bench.hard.verdicts import verdict
from formulations.kkt import final_status, qp_residuals
from formulations.solvers import get_solver
from formulations.solvers.active_set import cycling_qp
from formulations.solvers.backends import available_backends
from formulations.solvers.lcp import CYCLING_EXAMPLE
from formulations.solvers.registry import FAST_SOLVER, REFERENCE_SOLVER


@hard_case("cycling", "a contact QP on which the plain active-set iteration cycles "
                      "(formulations.solvers.lcp.CYCLING_EXAMPLE): the safeguard answers")
def cycling() -> list[dict]:
    qp, (_, _, start) = cycling_qp(), CYCLING_EXAMPLE
    runs = [(FAST_SOLVER, backend, {"warm_start": start.astype(float), "backend": backend})
            for backend in available_backends()] + [(REFERENCE_SOLVER, "clarabel", {})]
    records = []
    for solver, variant, options in runs:
        answer = get_solver(solver)(qp, **options)
        residuals = qp_residuals(qp, answer.u, answer.multipliers) \
            if answer.u is not None else None
        status, reason = final_status(answer, residuals)
        loss = max(vars(residuals).values()) if residuals is not None else np.nan
        diag = answer.diagnostics
        records.append(dict(
            case="cycling", scene="-", formulation="lcp", solver=solver, variant=variant,
            ndofs=qp.n, status=status, reason=answer.reason or reason, backend=answer.backend,
            safeguard=diag.safeguard, iterations=answer.iterations,
            max_residual=loss, loss=loss, pressure_loss=0.0,
            condition_estimate=diag.condition_estimate, verdict=verdict(status, loss),
            finding=(f"plain iteration cycled: {diag.cycled}; changes per "
                     f"iteration {','.join(map(str, diag.active_set_changes))}"
                     if solver == FAST_SOLVER else "interior point: no active sets")))
    return records

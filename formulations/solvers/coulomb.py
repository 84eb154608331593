"""Coulomb friction as a fixed point on the Tresca slip bound (docs/theory.md, 17.3).

b^0 = 0 (frictionless), then b^{k+1} = mu (lambda_n^k)^+, where lambda_n^k are the normal
reactions of the Tresca problem with bound b^k, until the bound changes by at most ``rtol``
relative to its size. For small mu the map contracts (Necas, Jarusek, Haslinger: the discrete
Coulomb problem has a unique solution for mu below a mesh-dependent constant); for large mu it
may not, and the solve then fails with the changes it saw, never with a half-converged answer
called ok. Every step solves a Tresca problem with whatever ``solve_tresca`` is given: the
exact active-set one, or the reference solver.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import numpy as np

from formulations.base import STATUS_FAILED, ContactQP, QPSolution

MAX_STEPS = 100


def coulomb_fixed_point(qp: ContactQP, solve_tresca: Callable[[ContactQP, QPSolution | None],
                                                              QPSolution],
                        rtol: float, max_steps: int = MAX_STEPS) -> QPSolution:
    """The Coulomb answer of ``qp`` (whose ``friction`` is Coulomb's); ``solve_tresca(qp,
    previous)`` solves one Tresca step, warm-started from the previous step's answer. A change
    that stops falling below ``rtol`` (a solver's own noise floor) is reported, not hidden."""
    friction = qp.friction
    bound = np.zeros(friction.bound.size)
    changes: list[float] = []
    answer, elapsed, steps = None, 0.0, 0
    for step in range(1, max_steps + 1):
        answer = solve_tresca(replace(qp, friction=friction.with_bound(bound)), answer)
        elapsed += answer.solve_time
        steps += answer.iterations
        if answer.status == STATUS_FAILED or answer.u is None:  # inaccurate: judged at the end
            return replace(answer, status=STATUS_FAILED, solve_time=elapsed,
                           reason=f"Coulomb fixed point, step {step}: {answer.reason}")
        new = friction.bounds(answer.multipliers)
        changes.append(float(np.abs(new - bound).max(initial=0.0)
                             / max(np.abs(new).max(initial=0.0), np.finfo(float).tiny)))
        bound = new
        if changes[-1] <= rtol:
            return replace(answer, iterations=steps, solve_time=elapsed,
                           reason=joined(answer.reason, f"Coulomb fixed point: {step} Tresca "
                                                         f"steps, last change {changes[-1]:.1e}"))
    ratio = changes[-1] / changes[-2] if len(changes) > 1 and changes[-2] > 0 else float("nan")
    return replace(answer, status=STATUS_FAILED, iterations=steps, solve_time=elapsed,
                   reason=f"Coulomb fixed point not converged after {max_steps} Tresca steps: "
                          f"bound still changing by {changes[-1]:.1e} (rtol {rtol:g}), last "
                          f"ratio of changes {ratio:.2f} (mu={friction.coefficient:g} too large "
                          "for the fixed point to contract)")


def joined(*parts: str) -> str:
    return "; ".join(part for part in parts if part)

"""Coulomb friction as a fixed point on the Tresca slip bound (docs/theory.md, 17.3).

b^0 = 0 (frictionless), then b^{k+1} = (1 - w) b^k + w mu (lambda_n^k)^+, where lambda_n^k are
the normal reactions of the Tresca problem with bound b^k, until mu (lambda_n^k)^+ differs from
b^k by at most ``rtol`` relative to its size. For small mu the map contracts with w = 1 (Necas,
Jarusek, Haslinger: the discrete Coulomb problem has a unique solution for mu below a
mesh-dependent constant); for large mu it may settle into a cycle (paper, vi P1, mu = 10: a
change of 3.5e-2 repeated for 200 steps). A step whose change is not below the last halves w
(down to 1/16): the same cycle then converges in 37 steps at w = 1/2. A slow but steady descent
keeps its w. If the changes still do not fall the solve fails with what it saw, never with a
half-converged answer called ok. Every step solves a Tresca problem with whatever
``solve_tresca`` is given: the exact active-set one, or the reference solver.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import numpy as np

from formulations.base import STATUS_FAILED, ContactQP, QPSolution

MAX_STEPS = 100
SLOW, SMALLEST_RELAXATION = 0.9, 1 / 16  # SLOW: what counts as settled at the noise floor


def coulomb_fixed_point(qp: ContactQP, solve_tresca: Callable[[ContactQP, QPSolution | None],
                                                              QPSolution],
                        rtol: float, noise_floor: float = 0.0,
                        max_steps: int = MAX_STEPS, zero: float = 0.0) -> QPSolution:
    """The Coulomb answer of ``qp`` (whose ``friction`` is Coulomb's); ``solve_tresca(qp,
    previous)`` solves one Tresca step, warm-started from the previous step's answer. It stops
    when the change is at most ``rtol``, or when it is at most ``noise_floor`` and no longer
    falls (not below 0.9 times the last): an inexact step solver's own noise, said in the
    reason. Bounds all at most ``zero`` (a force) are no contact: the change is then 0 (an
    interior point leaves multipliers of round-off size where nothing touches)."""
    friction = qp.friction
    bound = np.zeros(friction.bound.size)
    changes: list[float] = []
    answer, elapsed, steps, relaxation = None, 0.0, 0, 1.0
    for step in range(1, max_steps + 1):
        answer = solve_tresca(replace(qp, friction=friction.with_bound(bound)), answer)
        elapsed += answer.solve_time
        steps += answer.iterations
        if answer.status == STATUS_FAILED or answer.u is None:  # inaccurate: judged at the end
            return replace(answer, status=STATUS_FAILED, solve_time=elapsed,
                           reason=f"Coulomb fixed point, step {step}: {answer.reason}")
        new = friction.bounds(answer.multipliers)
        size = max(np.abs(new).max(initial=0.0), np.abs(bound).max(initial=0.0))
        changes.append(0.0 if size <= zero else float(
            np.abs(new - bound).max(initial=0.0) / max(np.abs(new).max(initial=0.0),
                                                       np.finfo(float).tiny)))
        settled = (len(changes) > 1 and changes[-1] <= noise_floor
                   and changes[-1] > SLOW * changes[-2])
        if len(changes) > 1 and changes[-1] >= changes[-2] and not settled:
            relaxation = max(relaxation / 2, SMALLEST_RELAXATION)  # a cycle, not a slow descent
        bound = (1 - relaxation) * bound + relaxation * new
        if changes[-1] <= rtol or settled:
            why = " (settled at the step solver's noise)" if changes[-1] > rtol else ""
            why += f", relaxation {relaxation:g}" if relaxation < 1 else ""
            return replace(answer, iterations=steps, solve_time=elapsed,
                           reason=joined(answer.reason, f"Coulomb fixed point: {step} Tresca "
                                                         f"steps, last change "
                                                         f"{changes[-1]:.1e}{why}"))
    ratio = changes[-1] / changes[-2] if len(changes) > 1 and changes[-2] > 0 else float("nan")
    return replace(answer, status=STATUS_FAILED, iterations=steps, solve_time=elapsed,
                   reason=f"Coulomb fixed point not converged after {max_steps} Tresca steps: "
                          f"bound still changing by {changes[-1]:.1e} (rtol {rtol:g}), last "
                          f"ratio of changes {ratio:.2f} at relaxation {relaxation:g} "
                          f"(mu={friction.coefficient:g} too large for the fixed point to "
                          "contract)")


def joined(*parts: str) -> str:
    return "; ".join(part for part in parts if part)

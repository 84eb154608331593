"""The semismooth Newton iteration on a ``Linearised`` problem, with its damped safeguard
(docs/theory.md, section 12.3): a step lands on the solution of the affine equation of its
active set, so the plain iteration is a primal-dual active set method; when it revisits a set
or does not settle, Newton with Armijo backtracking on |R|^2 continues from the best iterate.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from formulations.base import STATUS_FAILED, STATUS_OK

MERIT_TOLERANCE = 1e-13  # |R| relative to |z0| + |M phi| at which the damped phase stops
ARMIJO = 1e-4


@dataclass(frozen=True)
class NewtonResult:
    x: np.ndarray
    status: str
    reason: str
    iterations: int
    changes: tuple[int, ...]
    cycled: bool
    safeguard: str
    condition: float


@dataclass(frozen=True, eq=False)
class Linearised:
    """The problem in the unknown x (z condensed, or u): R(x), P(x), and ``step(A, x)``: the
    Newton step -J_A^-1 R_A(x) of the affine equation R_A for the active set A (phi with A
    fixed; R_A = R where A is x's own active set), with the 1-norm condition estimate of J_A."""

    residual: Callable[[np.ndarray], np.ndarray]
    argument: Callable[[np.ndarray], np.ndarray]
    step: Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, float]]
    scale: Callable[[np.ndarray], float]
    krylov: list[int] = field(default_factory=list)  # iterations per step (iterative back-end)
    # switch inexact steps to exact ones; True if they were inexact (the iteration goes on)
    tighten: Callable[[], bool] = lambda: False
    # an adaptive stopping rule's end at an iterate whose active set still changes
    settled: Callable[[np.ndarray], bool] = lambda x: False
    adaptive: object | None = None  # what keeps the stopping rule's state (its own module's)


def newton(problem: Linearised, x: np.ndarray, active: np.ndarray,
           max_iter: int) -> NewtonResult:
    """The plain iteration from ``x`` with the first step's active set ``active``, then the
    damped safeguard (module docstring)."""
    changes, seen, condition = [], {active.tobytes()}, float("nan")
    best = (np.inf, x)
    for iteration in range(1, max_iter + 1):
        r = problem.residual(x)
        best = min(best, (np.linalg.norm(r), x), key=lambda b: b[0])
        dx, condition = problem.step(active, x)
        x = x + dx
        new = problem.argument(x) < 0
        changes.append(int((new != active).sum()))
        if changes[-1] != 0 and problem.settled(x):
            return NewtonResult(x, STATUS_OK, "", iteration, tuple(changes), False, "",
                                condition)
        if changes[-1] == 0 and problem.tighten():  # settled inexactly: now solve exactly
            seen = {active.tobytes()}
            continue
        if changes[-1] == 0:
            return NewtonResult(x, STATUS_OK, "", iteration, tuple(changes), False, "",
                                condition)
        if new.tobytes() in seen and problem.tighten():  # inexact steps cycled: go on exactly
            seen = {new.tobytes()}
        elif new.tobytes() in seen:
            return damped(problem, best[1], iteration, tuple(changes), True,
                          "plain semismooth Newton revisited an active set")
        seen.add(new.tobytes())
        active = new
    return damped(problem, best[1], max_iter, tuple(changes), False,
                  f"plain semismooth Newton did not settle in {max_iter} iterations")


def damped(problem: Linearised, x: np.ndarray, done: int, changes: tuple[int, ...],
           cycled: bool, why: str, max_iter: int = 200) -> NewtonResult:
    """Newton with Armijo backtracking on |R|^2 from ``x``, its steps solved exactly (an
    iterative back-end's inexact search steps cannot reach MERIT_TOLERANCE)."""
    problem.tighten()
    r = problem.residual(x)
    condition = float("nan")
    for iteration in range(1, max_iter + 1):
        if np.linalg.norm(r) <= MERIT_TOLERANCE * problem.scale(x):
            return NewtonResult(x, STATUS_OK, f"{why}; answered by damped Newton (safeguard)",
                                done + iteration, changes, cycled, "damped Newton", condition)
        active = problem.argument(x) < 0
        dx, condition = problem.step(active, x)
        t, norm = 1.0, np.linalg.norm(r)
        while True:
            trial = problem.residual(x + t * dx)
            if np.linalg.norm(trial) <= (1.0 - ARMIJO * t) * norm or t < 1e-12:
                break
            t *= 0.5
        if t < 1e-12:
            break
        x, r = x + t * dx, trial
        changes += (int(((problem.argument(x) < 0) != active).sum()),)
    return NewtonResult(x, STATUS_FAILED, f"{why}; damped Newton stalled at |R| = "
                        f"{np.linalg.norm(r):.2e}", done + max_iter, changes, cycled,
                        "damped Newton", condition)

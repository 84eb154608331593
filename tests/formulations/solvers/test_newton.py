"""The semismooth Newton iteration on a ``Linearised`` problem: inexact steps that cycle are
redone exactly before any safeguard."""

import numpy as np

from formulations.solvers.newton import Linearised, newton


def two_set_problem():
    """x in R^1, active where x < 1/2. Inexact steps jump between 0 and 1 (the two active sets
    in turn); exact steps land on the solution 1/4."""
    exact = [False]

    def step(active, x):
        target = np.array([0.25]) if exact[0] else 1.0 - x
        return target - x, 1.0

    def tighten():
        looser, exact[0] = not exact[0], True
        return looser

    return Linearised(residual=lambda x: x - 0.25, argument=lambda x: x - 0.5, step=step,
                      scale=lambda x: 1.0, tighten=tighten)


def test_inexact_steps_that_revisit_a_set_go_on_exactly_instead_of_damping():
    result = newton(two_set_problem(), np.array([0.0]), np.array([True]), max_iter=20)
    assert result.status == "ok" and result.safeguard == "" and not result.cycled
    assert result.x[0] == 0.25  # exact: the step returns the target itself


def test_exact_steps_that_revisit_a_set_take_the_safeguard():
    problem = two_set_problem()
    problem.tighten()  # exact from the start: 1/4, then stays; now make it cycle exactly
    cycling = Linearised(residual=problem.residual, argument=problem.argument,
                         step=lambda active, x: (1.0 - 2 * x, 1.0), scale=problem.scale)
    result = newton(cycling, np.array([0.0]), np.array([True]), max_iter=20)
    assert result.cycled and result.safeguard == "damped Newton"

"""pytest-benchmark benchmarks of the dual-weighted estimate of the contact force against the
contact solve of the same mesh (``free-boundary:align_jump=1``, mixed and vi, P1, uniform:
8 320 DOFs, and 33 024 marked slow): the dual problem of order p + 1 has about four times the
primal's unknowns in 2D. The default test run executes the small one once; to measure::

    python -m pytest tests/benchmarks/test_goal_benchmarks.py -n 0 --dist no \
        --benchmark-enable --benchmark-only -m ""
"""

import pytest

from estimators.goals.dwr import estimate
from estimators.quantities import get_quantity
from formulations import get_formulation, solve
from scenes import get_scene

CASES = [pytest.param((f, r), id=f"{f}-{r}", marks=[pytest.mark.slow] if r > 4 else [])
         for f in ("mixed", "vi") for r in (4, 5)]


@pytest.fixture(scope="module", params=CASES)
def problem(request):
    formulation, refinements = request.param
    scene = get_scene("free-boundary", align_jump=1)
    disc = get_formulation(formulation)(scene, scene.mesh.refined(refinements))
    return scene, disc


def test_contact_solve(benchmark, problem):
    _, disc = problem
    solution = benchmark.pedantic(solve, args=(disc, "active-set"), rounds=3, iterations=1)
    assert solution.status == "ok", solution.reason
    benchmark.extra_info.update(ndofs=disc.ndofs)


def test_dwr_contact_force(benchmark, problem):
    scene, disc = problem
    solution = solve(disc, "active-set")
    quantity = get_quantity("contact-force", scene)
    goal = benchmark.pedantic(estimate, args=(scene, solution, quantity), rounds=3,
                              iterations=1)
    error = quantity.exact - goal.value
    # a correctness check of what was timed, not a timing: the estimate has the error's sign
    # on this uniform mesh for the mixed method (measured effectivity 1.00); vi's uniform
    # estimate is not judged (docs/theory.md, 20.4)
    if disc.formulation == "mixed":
        assert goal.estimate * error > 0
    benchmark.extra_info.update(ndofs=disc.ndofs, dual_dofs=goal.dual_dofs)

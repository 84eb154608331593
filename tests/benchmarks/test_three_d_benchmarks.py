"""pytest-benchmark benchmarks of the guaranteed bound on tetrahedra against the contact solve
of the same mesh (``free-boundary-3d``, vi, P1, uniform: 1 944 and 13 872 DOFs; the second is
marked slow). The default test run executes the small one once; to measure::

    python -m pytest tests/benchmarks/test_three_d_benchmarks.py -n 0 --dist no \
        --benchmark-enable --benchmark-only -m ""
"""

import pytest

from bench.measure.discretisation_error import exact_errors
from estimators import get_estimator
from formulations import get_formulation, solve
from scenes import get_scene

SIZES = [1, pytest.param(2, marks=pytest.mark.slow)]
ROUNDS = {1: 5, 2: 3}


@pytest.fixture(scope="module", params=SIZES)
def problem(request):
    scene = get_scene("free-boundary-3d")
    disc = get_formulation("vi")(scene, scene.mesh.refined(request.param))
    return request.param, scene, disc


def test_contact_solve_3d(benchmark, problem):
    refinements, _, disc = problem
    solution = benchmark.pedantic(solve, args=(disc, "active-set"), rounds=ROUNDS[refinements],
                                  iterations=1)
    assert solution.status == "ok", solution.reason
    benchmark.extra_info.update(ndofs=disc.ndofs)


def test_equilibrated_3d(benchmark, problem):
    refinements, scene, disc = problem
    solution = solve(disc, "active-set")
    estimate = benchmark.pedantic(get_estimator("equilibrated"), args=(scene, solution),
                                  rounds=ROUNDS[refinements], iterations=1)
    error = exact_errors(scene, solution).energy_error
    # guaranteed: eta >= ||u - u_h|| (docs/theory.md 13.1, 14.5)
    assert estimate.eta >= error
    benchmark.extra_info.update(ndofs=disc.ndofs, eta=float(estimate.eta),
                                effectivity=float(estimate.eta / error))

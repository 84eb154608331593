"""pytest-benchmark benchmarks of every phase at ~10^4, 10^5 and 10^6 DOFs (paper scene, mixed
method, uniform mesh; the workloads of ``python -m bench scaling``).

The default test run executes the 10^4 size once (``--benchmark-disable`` in pyproject) so the
benchmarks cannot rot. To measure (10^5 is marked slow, 10^6 long; ``-m ""`` selects all, and
``-n 0 --dist no`` runs them in one process: pytest-benchmark measures nothing under xdist)::

    python -m pytest tests/benchmarks -n 0 --dist no --benchmark-enable --benchmark-only -m "" \
        --benchmark-json=benchmarks.json

The reference solver is benchmarked at 10^4 and 10^5 only: at 10^6 DOFs one Clarabel solve
takes minutes (see the scaling table in docs/solvers.md), too long to repeat.
"""

import numpy as np
import pytest

from bench.perf.scaling import linear_rhs, paper_problem
from estimators import estimator_names, get_estimator
from estimators.base import ESTIMATORS
from formulations import get_formulation, solve
from formulations.diagnostics import inf_sup_constant, pressure_oscillation
from formulations.solvers.backends import default_backend, factorise

SIZES = ["1e4", pytest.param("1e5", marks=pytest.mark.slow),
         pytest.param("1e6", marks=pytest.mark.long)]
ROUNDS = {"1e4": 5, "1e5": 3, "1e6": 1}


@pytest.fixture(scope="module", params=SIZES)
def problem(request):
    scene, mesh = paper_problem(request.param)
    disc = get_formulation("mixed")(scene, mesh)
    return request.param, scene, mesh, disc


def _info(benchmark, disc, **more):
    benchmark.extra_info.update(ndofs=disc.ndofs, n_constraints=disc.qp.m,
                                backend=default_backend(), **more)


def _residuals(solution) -> dict:
    return {name: float(value) for name, value in vars(solution.residuals).items()}


def test_assembly(benchmark, problem):
    size, scene, mesh, disc = problem
    result = benchmark.pedantic(get_formulation("mixed"), args=(scene, mesh),
                                rounds=ROUNDS[size], iterations=1)
    assert result.ndofs == disc.ndofs
    _info(benchmark, disc)


def test_linear_solve(benchmark, problem):
    size, _, _, disc = problem

    b = linear_rhs(disc.qp)

    def linear_solve():
        return factorise(disc.qp.K)(b)

    u = benchmark.pedantic(linear_solve, rounds=ROUNDS[size], iterations=1)
    residual = np.linalg.norm(disc.qp.K @ u - b) / np.linalg.norm(b)
    assert residual < 1e-10  # a direct solve of an SPD system with cond ~ 1e5: round-off
    _info(benchmark, disc, relative_residual=float(residual))


def test_fast_contact_solve(benchmark, problem):
    size, _, _, disc = problem
    sol = benchmark.pedantic(solve, args=(disc, "active-set"), rounds=ROUNDS[size], iterations=1)
    assert sol.status == "ok", sol.reason
    _info(benchmark, disc, iterations=sol.iterations, **_residuals(sol))


@pytest.fixture(scope="module")
def solution(problem):
    return solve(problem[3], "active-set")


@pytest.mark.parametrize("estimator", estimator_names())
def test_estimator(benchmark, problem, solution, estimator):
    size, scene, _, disc = problem
    why = ESTIMATORS.why_not(estimator, scene=scene, formulation="mixed")
    if why is not None:
        pytest.skip(why)
    est = benchmark.pedantic(get_estimator(estimator), args=(scene, solution),
                             rounds=ROUNDS[size], iterations=1)
    assert np.isfinite(est.eta) and est.eta > 0
    _info(benchmark, disc, eta=float(est.eta))


def test_stability_diagnostics(benchmark, problem, solution):
    # the loop's diagnostic columns: the inf-sup constant (one factorisation of K and one solve
    # per multiplier segment) and the pressure oscillation
    size, _, _, disc = problem

    def diagnose():
        return inf_sup_constant(disc), pressure_oscillation(solution)

    beta, oscillation = benchmark.pedantic(diagnose, rounds=ROUNDS[size], iterations=1)
    # h/H = 1/2 on uniform meshes: beta ~ 0.53; the oscillation is >= 1 up to the round-off of
    # its sum of differences (see tests/bench/sequence/test_loop.py): 1e-12 slack
    assert beta > 0.5 and oscillation >= 1.0 - 1e-12
    _info(benchmark, disc, inf_sup=beta, pressure_oscillation=oscillation)


@pytest.mark.parametrize("size", ["1e4", pytest.param("1e5", marks=pytest.mark.slow)])
def test_reference_solve(benchmark, size):
    scene, mesh = paper_problem(size)
    disc = get_formulation("mixed")(scene, mesh)
    sol = benchmark.pedantic(solve, args=(disc, "reference"), rounds=min(ROUNDS[size], 2),
                             iterations=1)
    assert sol.status == "ok", sol.reason
    _info(benchmark, disc, iterations=sol.iterations, **_residuals(sol))

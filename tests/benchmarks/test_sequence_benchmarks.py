"""pytest-benchmark benchmarks of adaptive refinement (marking included) and of whole
sequences at ~10^4 and 10^5 DOFs (10^6 marked long): the paper scene, mixed method, active set,
residual estimator, the workloads of ``python -m bench scaling --sequence`` without the error
against the reference. Run and compared as docs/solvers.md, "Benchmarks", says."""

import pytest

from bench.measure.contact import SOLVED_STATUSES as SOLVED
from bench.perf.scaling import paper_problem
from bench.sequence.loop import LoopConfig, refine, run_sequence
from estimators import get_estimator
from formulations import get_formulation, solve
from formulations.solvers.registry import FAST_SOLVER
from scenes import get_scene

SIZES = ["1e4", "1e5", pytest.param("1e6", marks=pytest.mark.long)]
BUDGETS = {"1e4": 10_000, "1e5": 100_000, "1e6": 1_000_000}
ROUNDS = {"1e4": 5, "1e5": 3, "1e6": 1}
ADAPTIVE = LoopConfig(strategy="adaptive")  # Doerfler, theta = 0.5, contact grading


@pytest.fixture(scope="module", params=SIZES)
def estimated(request):
    scene, mesh = paper_problem(request.param)
    solution = solve(get_formulation("mixed")(scene, mesh), FAST_SOLVER)
    return request.param, mesh, solution, get_estimator("residual")(scene, solution)


def test_adaptive_refinement(benchmark, estimated):
    size, mesh, solution, estimate = estimated
    finer = benchmark.pedantic(refine, args=(mesh, solution, estimate, ADAPTIVE),
                               rounds=ROUNDS[size], iterations=1)
    # Doerfler with theta = 0.5 marks a fraction of the elements: more, but not all, split
    assert mesh.t.shape[1] < finer.t.shape[1] < 4 * mesh.t.shape[1]
    benchmark.extra_info.update(elements=int(mesh.t.shape[1]),
                                refined_elements=int(finer.t.shape[1]))


@pytest.mark.parametrize("strategy", ["adaptive", "uniform"])
@pytest.mark.parametrize("size", SIZES)
def test_sequence(benchmark, size, strategy):
    scene = get_scene("paper")
    config = LoopConfig(strategy=strategy, max_dofs=BUDGETS[size], max_levels=60)

    def sequence():
        return [result.row for result in run_sequence(scene, "mixed", FAST_SOLVER, "residual",
                                                      config)]

    rows = benchmark.pedantic(sequence, rounds=ROUNDS[size], iterations=1)
    assert all(row.status in SOLVED for row in rows)
    # the budget is reached: the last level is within one refinement of it (adaptive levels
    # grow N by ~1.7x, uniform ones by ~4x)
    assert BUDGETS[size] / 4.5 < rows[-1].ndofs <= BUDGETS[size]
    benchmark.extra_info.update(levels=len(rows), final_ndofs=int(rows[-1].ndofs))

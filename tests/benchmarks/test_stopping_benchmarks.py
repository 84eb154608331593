"""pytest-benchmark benchmarks of one nested contact solve on the amg back-end with the fixed
tolerances and with the adaptive stopping rule (docs/theory.md, 18): free-boundary, vi, P1,
the level reached by uniform refinement from the previous level's solution (its contact zone
and its displacement as the start), at ~1.3e5 DOFs (5e5 marked long). The expected eta_disc
is the previous level's error bound times 2^-1 (the optimal rate over one uniform refinement
in 2D), as the refinement loop predicts it."""

import pytest

from bench.sequence.nested import initial_displacement
from estimators.base import estimator_on
from estimators.guaranteed.constants import domain_constants
from formulations import get_formulation, solve
from formulations.hat_loads import load_norm
from formulations.solvers.registry import FAST_SOLVER
from formulations.solvers.stopping import ADAPTIVE, FIXED, Stopping
from scenes import get_scene

pytestmark = pytest.mark.slow
SIZES = {"1e5": 5, "5e5": 6}  # uniform refinements of free-boundary before the solved level


@pytest.fixture(scope="module", params=["1e5", pytest.param("5e5", marks=pytest.mark.long)])
def nested_level(request):
    scene = get_scene("free-boundary")
    coarse = scene.mesh.refined(SIZES[request.param])
    formulation = get_formulation("vi")
    previous = solve(formulation(scene, coarse), FAST_SOLVER, backend="amg")
    bound = estimator_on("equilibrated", "tri")(scene, previous).eta
    disc = formulation(scene, coarse.refined(1))
    options = dict(backend="amg", warm_start=disc.warm_start(previous, FAST_SOLVER),
                   initial=initial_displacement(previous, disc))
    norm = load_norm(disc.elasticity, domain_constants(scene).friedrichs)
    return disc, options, norm, bound / 2


@pytest.mark.parametrize("rule", [FIXED, ADAPTIVE])
def test_nested_amg_solve(benchmark, nested_level, rule):
    disc, options, norm, expected = nested_level
    stopping = Stopping(rule, norm, expected_disc=expected)
    solution = benchmark.pedantic(solve, args=(disc, FAST_SOLVER), kwargs=dict(
        stopping=stopping, **options), rounds=3, iterations=1)
    assert solution.ok and not solution.diagnostics.safeguard
    parts = solution.components
    if rule == ADAPTIVE:  # the rule's own promise, checked from the returned arrays
        assert parts.eta_alg <= 1.1 * 0.1 * (expected + parts.eta_lin)
    benchmark.extra_info.update(ndofs=disc.ndofs, eta_alg=parts.eta_alg, eta_lin=parts.eta_lin,
                                krylov_iterations=sum(solution.diagnostics.krylov_iterations),
                                newton_steps=solution.iterations)

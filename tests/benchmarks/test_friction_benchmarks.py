"""pytest-benchmark benchmarks of the frictional solves against the linear solve of the same K
(paper scene with Tresca s = 300 N/mm^2 and Coulomb mu = 0.3, vi P1, uniform meshes of about
10^4, 10^5 and 10^6 DOFs; docs/theory.md, 17.6). Run them as tests/benchmarks/test_benchmarks.py
says; the default test run executes 10^4 once."""

import numpy as np
import pytest

from bench.perf.scaling import SIZES, linear_rhs
from formulations import get_formulation, solve
from formulations.solvers.backends import default_backend, factorise
from scenes import get_scene

SIZE_PARAMS = ["1e4", pytest.param("1e5", marks=pytest.mark.slow),
               pytest.param("1e6", marks=pytest.mark.long)]
ROUNDS = {"1e4": 5, "1e5": 3, "1e6": 1}
LAWS = {"tresca": dict(friction="tresca", slip_bound=300.0),
        "coulomb": dict(friction="coulomb", mu=0.3)}


@pytest.fixture(scope="module", params=SIZE_PARAMS)
def size(request):
    return request.param


def discretised(size: str, law: str):
    divisions, refinements = SIZES[size]
    scene = get_scene("paper", initial_divisions=divisions, **LAWS[law])
    return get_formulation("vi")(scene, scene.mesh.refined(refinements))


def test_linear_solve_of_the_same_k(benchmark, size):
    disc = discretised(size, "tresca")
    b = linear_rhs(disc.qp)
    u = benchmark.pedantic(lambda: factorise(disc.qp.K)(b), rounds=ROUNDS[size], iterations=1)
    # a direct solve of an SPD system with cond ~ 1e5: round-off
    assert np.linalg.norm(disc.qp.K @ u - b) < 1e-10 * np.linalg.norm(b)
    benchmark.extra_info.update(ndofs=disc.ndofs, backend=default_backend())


@pytest.mark.parametrize("law", sorted(LAWS))
def test_frictional_solve(benchmark, size, law):
    disc = discretised(size, law)
    sol = benchmark.pedantic(solve, args=(disc, "active-set"), rounds=ROUNDS[size],
                             iterations=1)
    assert sol.status == "ok", sol.reason
    assert max(vars(sol.residuals).values()) < 1e-9  # exact sets; Coulomb stops at 1e-11
    benchmark.extra_info.update(ndofs=disc.ndofs, backend=sol.backend,
                                iterations=sol.iterations,
                                stick=int((sol.friction.state == "stick").sum()),
                                slip=int((sol.friction.state == "slip").sum()))

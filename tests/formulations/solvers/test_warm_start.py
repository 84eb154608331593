"""Nested iteration's warm start fits the problem the solver solves: the semismooth system's
Gauss points, or the rows of the slack QP of the same formulation (formulations.base.slack_qp)."""

import numpy as np
import pytest

from formulations import get_formulation, solve
from formulations.solvers.registry import SOLVERS
from scenes import get_scene


@pytest.mark.parametrize("formulation", ["penalty", "nitsche"])
def test_a_qp_solver_gets_a_warm_start_of_the_qps_rows(formulation):
    scene = get_scene("paper")
    coarse = solve(get_formulation(formulation)(scene, scene.mesh.refined(2)), "active-set")
    fine = get_formulation(formulation)(scene, scene.mesh.refined(3))
    assert fine.warm_start(coarse, "active-set").shape == (fine.system.nq,)
    warm = fine.warm_start(coarse, "reference")
    assert warm.shape == (fine.qp.m,) == (2 * fine.system.nq,)
    # each Gauss point has exactly one of its two rows active: u_n - s <= g or s >= 0
    assert np.array_equal(warm[:fine.system.nq] + warm[fine.system.nq:],
                          np.ones(fine.system.nq))
    # a solver with a method for the QP only (as a plugin may register) runs from it
    answer = SOLVERS.get("active-set")(fine.qp, warm_start=warm)
    cold = SOLVERS.get("active-set")(fine.qp)
    assert answer.status == cold.status == "ok"
    # the same minimiser, to round-off in u (both are exact at convergence)
    assert np.abs(answer.u - cold.u).max() <= 1e-10 * np.abs(cold.u).max()

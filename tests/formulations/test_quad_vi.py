"""The VI on quadrilaterals (Q1, Q2, hanging nodes included): a rigid flat pressing the body
up is reproduced exactly, and the fast active-set solve agrees with Clarabel."""

import numpy as np
import pytest

from conftest import square_scene
from formulations.quad_vi import solve_quad_vi
from scenes import get_scene
from scenes.quad_hierarchy import QuadHierarchy


def hierarchy_with_hanging_nodes() -> QuadHierarchy:
    return QuadHierarchy.from_tensor(np.linspace(-1, 1, 5), np.linspace(-1, 1, 5)) \
        .refined([0, 5]).refined([1])


@pytest.mark.parametrize("order", [1, 2])
def test_a_flat_push_is_reproduced(compression_scene, order):
    """u = (0, delta (1 - y) / 2), pressure E delta / 2 on all of Gamma_C (conftest): linear,
    so in Q1 and Q2; energy 1/2 (E delta^2 / 4) |Omega| = 0.05, force 10."""
    solution = solve_quad_vi(compression_scene, hierarchy_with_hanging_nodes(), order)
    assert solution.status == "ok"
    assert solution.energy == pytest.approx(0.05, rel=1e-12)  # round-off of a direct solve
    assert solution.contact_force == pytest.approx(10.0, rel=1e-12)
    basis = solution.elasticity.basis
    uy = solution.u[basis.nodal_dofs[1]]
    assert np.allclose(uy, 0.005 * (1 - basis.mesh.p[1]), atol=1e-14)


@pytest.mark.parametrize("order", [1, 2])
def test_the_fast_solve_agrees_with_the_reference_solver(order):
    scene = get_scene("paper")
    hierarchy = QuadHierarchy.from_tensor(np.linspace(-1, 1, 9), np.linspace(-1, 1, 9))
    hierarchy = hierarchy.refined(np.arange(8))  # the bottom row: hanging nodes above it
    assert hierarchy.hanging()[0].size > 0
    fast = solve_quad_vi(scene, hierarchy, order, "active-set")
    judge = solve_quad_vi(scene, hierarchy, order, "reference")
    # Clarabel's interior point stops at a relative gap of about 1e-8
    assert fast.energy == pytest.approx(judge.energy, rel=1e-7)
    assert fast.contact_force == pytest.approx(judge.contact_force, rel=1e-6)


def test_an_empty_contact_zone_is_a_free_solve(free_scene):
    hierarchy = QuadHierarchy.from_tensor(np.linspace(-1, 1, 5), np.linspace(-1, 1, 5))
    solution = solve_quad_vi(free_scene, hierarchy, 1)
    assert solution.status == "ok" and solution.contact_force == 0.0
    assert solution.energy < 0  # a body force with nothing in the way: E(u) = -F'u / 2


def test_a_scene_without_contact_rows_is_not_confused_with_one(compression_scene):
    lifted = square_scene(lambda x: np.full(x.shape[1:], 1.0))
    assert solve_quad_vi(lifted, hierarchy_with_hanging_nodes(), 1).contact_force == 0.0

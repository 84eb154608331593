"""The dual problem at the discrete contact set: it holds its constraint, and its reactions
obey the identity a(z, z) + (pi, omega) = j(z) that testing its own equation with v = z gives
(j = 0 for the contact force, so sum pi_i = -a(z, z) with omega = 1)."""

import numpy as np
import pytest

import estimators.quantities as Q
from estimators.goals.dual import solve_dual
from formulations import get_formulation, solve
from formulations.cells import family_for
from scenes.registry import get_scene


@pytest.fixture(scope="module", params=["mixed", "vi"])
def solved(request):
    scene = get_scene("hertz")
    mesh = family_for("tri", 2).starting_mesh(scene).refined(2)
    return scene, solve(get_formulation(request.param)(scene, mesh, order=1), "active-set")


def test_the_dual_holds_its_normal_displacement_on_the_contact_set(solved):
    scene, solution = solved
    dual = solve_dual(scene, solution, Q.get_quantity("contact-force", scene))
    assert dual.points.shape[1] > 0
    # omega = 1 imposed as a Dirichlet value in the rotated frame: exact up to round-off
    np.testing.assert_allclose(dual.normal_rows @ dual.z, 1.0, atol=1e-12)


def test_the_reactions_balance_the_dual_energy(solved):
    scene, solution = solved
    dual = solve_dual(scene, solution, Q.get_quantity("contact-force", scene))
    energy = dual.z @ (dual.elasticity.K @ dual.z)
    # one linear solve's round-off relative to a(z, z)
    assert dual.reaction.sum() == pytest.approx(-energy, rel=1e-8)


def test_a_goal_with_a_load_is_the_load_tested_with_z(solved):
    scene, solution = solved
    quantity = Q.get_quantity("point-displacement", scene)
    dual = solve_dual(scene, solution, quantity)
    from estimators.goals.dual import dual_load

    load = dual_load(dual.elasticity, quantity)
    z_free = dual.z[dual.elasticity.free]
    # omega = 0 on the contact set: a(z, z) = j(z), to round-off
    assert z_free @ (dual.elasticity.K_free @ z_free) == pytest.approx(load @ z_free, rel=1e-8)

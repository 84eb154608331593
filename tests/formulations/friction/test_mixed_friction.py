"""Friction in the mixed method: a tangential multiplier in the normal one's space and the
bounds on its Bernstein coefficients (the fast solve against the reference:
test_friction_agreement.py)."""

import numpy as np
import pytest

from formulations import get_formulation, solve
from scenes import get_scene


def test_the_coulomb_bound_holds_everywhere_on_each_segment():
    scene = get_scene("stick-slip", friction="coulomb")
    disc = get_formulation("mixed")(scene, scene.mesh.refined(3), order=3)
    solution = solve(disc, "active-set")
    t = np.linspace(0.0, 1.0, 21)
    shear, pressure = solution.friction.traction(t), solution.pressure(t)
    # the Bernstein convex hull: |lambda_t,H| <= mu lambda_n,H wherever the coefficients obey
    # it (round-off of the exact sets: 1e-12 of the largest pressure)
    assert (np.abs(shear) <= 0.3 * pressure + 1e-12 * pressure.max()).all()
    assert (solution.friction.state == "slip").any() and (solution.friction.state == "stick").any()


def test_the_tresca_bound_of_a_piecewise_constant_multiplier_is_the_mean_of_s():
    scene = get_scene("paper", friction="tresca", slip_bound=300.0)
    disc = get_formulation("mixed")(scene, scene.mesh.refined(2))
    # a constant s: every coefficient's bound is s itself (the exact mean)
    assert disc.qp.friction.bound == pytest.approx(300.0, rel=1e-14)
    # the tangential rows integrate u . t over each segment: a unit x-translation gives the
    # segment lengths H (t = (1, 0) on the bottom edge)
    unit = np.zeros(disc.elasticity.basis.N)
    unit[disc.elasticity.basis.nodal_dofs[0]] = 1.0
    lengths = disc.qp.friction.T @ unit[disc.elasticity.free]
    assert lengths == pytest.approx(disc.qp.row_scale, rel=1e-12)

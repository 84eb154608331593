"""Friction in Nitsche's method (theta = 1): the projected Nitsche traction at every point,
theta != 1 refused (the fast solve against the reference: test_friction_agreement.py)."""

import numpy as np
import pytest

from formulations import get_formulation, solve
from scenes import get_scene


def test_the_tangential_traction_is_the_projected_nitsche_traction():
    scene = get_scene("stick-slip")
    disc = get_formulation("nitsche")(scene, scene.mesh.refined(3))
    solution = solve(disc, "active-set")
    state = solution.friction
    # sigma_t,h = [sigma_nt(u_h) - gamma u_t]_s at the Gauss points, from the QP's
    # multipliers (shear) and from u_h alone (traction): two routes, one answer up to the
    # exact active sets' round-off
    t, _ = disc.trace.rule(2)
    along = state.traction(t).ravel()
    assert state.shear == pytest.approx(along, abs=1e-9 * np.abs(along).max())
    assert np.all(np.abs(along) <= state.bound_traction * (1 + 1e-12))
    assert set(state.state) == {"stick", "slip", "separated"}


def test_theta_other_than_one_is_refused_with_friction():
    scene = get_scene("stick-slip")
    with pytest.raises(ValueError, match=r"theta=0 with friction \(tresca\) is not allowed"):
        get_formulation("nitsche")(scene, scene.mesh, theta=0.0)

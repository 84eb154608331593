"""Friction in the penalty method: the regularised law at every point (the fast solve against
the reference: test_friction_agreement.py)."""

import numpy as np
import pytest

from formulations import get_formulation, solve
from scenes import get_scene


def test_the_tangential_traction_is_the_projected_regularised_slip():
    scene = get_scene("stick-slip")
    disc = get_formulation("penalty")(scene, scene.mesh.refined(3))
    qp, solution = disc.qp, solve(disc, "active-set")
    n, ns = disc.elasticity.free.size, disc.qp.m
    u = solution.u[disc.elasticity.free]
    # lambda_t = P_[-b, b](D (u_t - w)) at every point (w = 0 here; D the slacks' weight
    # w_q |e| / eps): the Huber energy's derivative, a formula independent of the solver;
    # the exact active sets leave round-off
    D = qp.K.diagonal()[n + ns:]
    expected = np.clip(D * (qp.friction.T[:, :n] @ u), -qp.friction.bound, qp.friction.bound)
    got = solution.friction.tangential_reactions
    assert got == pytest.approx(expected, abs=1e-9 * np.abs(expected).max())
    state = solution.friction.state
    assert (state == "stick").any() and (state == "slip").any()

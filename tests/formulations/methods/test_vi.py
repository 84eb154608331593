"""The nodal variational inequality: no nodal penetration, non-negative reactions."""

import numpy as np
import pytest

from formulations import get_formulation, solve
from scenes import get_scene


@pytest.fixture(scope="module", params=["active-set", "reference"])
def solved(request):
    scene = get_scene("paper")
    disc = get_formulation("vi")(scene, scene.mesh.refined(3))
    sol = solve(disc, request.param)
    assert sol.status == "ok", sol.reason
    return scene, disc, sol


def test_no_nodal_penetration(solved):
    scene, disc, sol = solved
    nodes = sol.details.contact_nodes
    u = sol.elasticity.nodal(sol.u)[:, nodes]
    u_n = -u[1]  # outer normal (0, -1) on the bottom edge
    g = scene.gap(scene.mesh.refined(3).p[:, nodes])
    # Clarabel's feasibility tolerance 1e-10 relative to the displacement scale ~0.15
    assert (u_n - g).max() <= 1e-9
    assert np.isclose(u_n - g, 0.0, atol=1e-9).sum() == sol.active_constraints


def test_reactions_are_non_negative_and_balance_the_pressure(solved):
    _, disc, sol = solved
    reactions = sol.details.reactions
    # the reactions are the reference solver's multipliers, >= 0 up to its relative tolerance
    # 1e-9 (Clarabel's 1e-10 on the scaled problem, 10x for the rescaling)
    assert reactions.min() >= -1e-9 * reactions.max() and reactions.max() > 0.0
    # lumped recovery: int lambda_h = sum of the reactions up to the lumping of the ends of
    # the contact zone (one facet each); measured 0.3 % here
    assert sol.contact_force() == pytest.approx(reactions.sum(), rel=0.02)


def test_vi_and_mixed_agree_on_a_fine_mesh():
    scene = get_scene("paper")
    mesh = scene.mesh.refined(4)
    vi = solve(get_formulation("vi")(scene, mesh), "active-set")
    mixed = solve(get_formulation("mixed")(scene, mesh), "active-set")
    assert vi.energy == pytest.approx(mixed.energy, rel=2e-3)  # measured 1.1e-3

"""Trace and Friedrichs constants from the geometry (estimators.guaranteed.proved_constants and
estimators.guaranteed.chained_constants): exact rigid motion integrals, the convexity the whole
domain's bound needs, and upper bounds of the discrete suprema of estimators.guaranteed.constants,
which approach the true constants from below."""

from pathlib import Path

import numpy as np
import pytest
from skfem import MeshTri

from estimators.guaranteed.chained_constants import side_rule, triangle_rule
from estimators.guaranteed.constants import domain_constants
from estimators.guaranteed.proved_constants import Outline, proved_constants, rigid_gram
from scenes import get_scene
from scenes.declarative import register_toml_scene

EXAMPLES = Path(__file__).parents[3] / "examples"


def test_rigid_motion_integrals_are_exact_on_the_unit_square():
    mesh = MeshTri().refined(2)
    centre = np.array([0.5, 0.5])
    # int over (0, 1)^2 of 1, 1 and |x - centre|^2 = 2 / 12; about the centroid the rotation
    # is orthogonal to the translations
    expected = np.diag([1.0, 1.0, 1.0 / 6.0])
    assert np.allclose(rigid_gram(triangle_rule(mesh), centre), expected, atol=1e-14)
    bottom = mesh.facets_satisfying(lambda x: x[1] < 1e-12, boundaries_only=True)
    # on y = 0 the rotation is (0.5, x - 0.5): int 1 = 1, int 0.5 = 0.5, int 0.25 + (x - 0.5)^2
    # = 1 / 3, int (x - 0.5) = 0
    expected = np.array([[1.0, 0.0, 0.5], [0.0, 1.0, 0.0], [0.5, 0.0, 1.0 / 3.0]])
    assert np.allclose(rigid_gram(side_rule(mesh, bottom), centre), expected, atol=1e-14)


def test_convexity_of_the_outline():
    assert Outline.of(MeshTri().refined(2)).convex()
    assert not Outline.of(MeshTri.init_lshaped().refined(1)).convex()


def _check_above_computed(scene, most: float):
    proved, computed = proved_constants(scene), domain_constants(scene)
    # the discrete suprema (and their extrapolation) lie below the true constants, so a
    # proved bound below them would be wrong
    assert proved.trace > computed.trace
    assert proved.friedrichs > computed.friedrichs
    # and within ``most`` times them: the proofs lose a factor 10 .. 80 (docs/theory.md 13.4);
    # losing a further one (K, the trace's 2 / m, a Gram matrix) fails this
    assert proved.trace < most * computed.trace
    assert proved.friedrichs < most * computed.friedrichs
    return proved


@pytest.mark.parametrize("name", ["paper", "hertz", "thin", "grazing"])
def test_proved_constants_bound_the_discrete_suprema(name):
    proved = _check_above_computed(get_scene(name), 100.0)
    assert proved.convex is not None  # the built-in domains are rectangles
    # each of the two proofs holds; the smaller is taken
    assert proved.trace == min(proved.convex[0], proved.chained[0])
    assert proved.friedrichs == min(proved.convex[1], proved.chained[1])


def test_the_chain_serves_where_the_domain_is_thin_or_not_convex():
    # thin: the whole domain's Korn constant is 2e4 (angle 1.1 degrees), the chain's 1e2 x
    # smaller; a domain with a hole has no whole-domain bound at all
    thin = proved_constants(get_scene("thin"))
    assert thin.chained[0] < 0.01 * thin.convex[0]
    holed = get_scene(register_toml_scene(EXAMPLES / "holed_block.toml"))
    proved = _check_above_computed(holed, 200.0)
    assert proved.convex is None and proved.trace == proved.chained[0]


def test_the_whole_square_by_hand():
    # paper: (-1, 1)^2 clamped on top, in contact below. Seen from the centre the Horgan-Payne
    # angle is 45 degrees, (x - c) . n = 1 on every side, |x - c| <= 2^(1/2), diameter
    # 2 2^(1/2); the rigid motions (1, 0), (0, 1), (-y, x) integrate to these Gram matrices
    scene = get_scene("paper")
    lam, mu = scene.material.lame
    korn = 2 / np.sin(np.pi / 8) ** 2
    poincare = 2 * np.sqrt(2) / np.pi
    boundary = np.sqrt(2 * (poincare**2 + np.sqrt(2) * poincare))
    top = np.array([[2, 0, -2], [0, 2, 0], [-2, 0, 8 / 3]])
    bottom = np.array([[2, 0, 2], [0, 2, 0], [2, 0, 8 / 3]])
    square = np.diag([4, 4, 8 / 3])
    g_domain = np.sqrt(np.linalg.eigvals(np.linalg.solve(top, square)).real.max())
    g_contact = np.sqrt(np.linalg.eigvals(np.linalg.solve(top, bottom)).real.max())
    scale = np.sqrt(korn / (2 * mu))
    trace, friedrichs = proved_constants(scene).convex
    # the same arithmetic in another order: round-off only
    assert trace == pytest.approx((1 + g_contact) * boundary * scale, rel=1e-12)
    assert friedrichs == pytest.approx((poincare + g_domain * boundary) * scale, rel=1e-12)

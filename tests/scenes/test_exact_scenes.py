"""The exact-answer scenes: their data fit their solutions (checked by finite differences)."""

import numpy as np
import pytest

from formulations.elasticity import stress_from_gradient
from scenes import get_scene
from scenes.hertz import hertz_prediction

STEP = 1e-5


def test_free_boundary_gradient_and_body_force_by_finite_differences():
    scene = get_scene("free-boundary")
    exact, (lam, mu) = scene.exact, scene.material.lame
    rng = np.random.default_rng(1)
    x = rng.uniform(-0.95, 0.95, size=(2, 200))
    x = x[:, np.abs(np.abs(x[0]) - 0.4) > 1e-3]  # f jumps at |x| = a
    for j in (0, 1):
        e = np.zeros((2, 1))
        e[j] = STEP
        fd = (exact.displacement(x + e) - exact.displacement(x - e)) / (2 * STEP)
        assert fd == pytest.approx(exact.gradient(x)[:, j], abs=1e-8)
    # f = -div sigma(u), sigma from the exact gradient, differentiated numerically
    div = np.zeros_like(x)
    for j in (0, 1):
        e = np.zeros((2, 1))
        e[j] = STEP
        sp, sm = (stress_from_gradient(exact.gradient(x + s * e), lam, mu) for s in (1, -1))
        tensor = lambda s: np.array([[s[0], s[2]], [s[2], s[1]]])  # noqa: E731
        div += (tensor(sp)[:, j] - tensor(sm)[:, j]) / (2 * STEP)
    assert scene.body_force(x) == pytest.approx(-div, abs=1e-6 * np.abs(div).max())


def test_free_boundary_signorini_conditions_hold_on_the_contact_edge():
    scene = get_scene("free-boundary")
    exact, (lam, mu) = scene.exact, scene.material.lame
    s = np.linspace(-1, 1, 401)
    x = np.array([s, -np.ones_like(s)])
    s11, s22, s12 = stress_from_gradient(exact.gradient(x), lam, mu)
    u_n = -exact.displacement(x)[1]
    gap = scene.gap(x)
    pressure = exact.pressure(s)
    assert s12 == pytest.approx(0.0, abs=1e-15)  # frictionless
    assert -s22 == pytest.approx(pressure, abs=1e-15)  # sigma_nn = sigma_yy = -lambda
    # pressure: exact, a square root of a clipped value; u_n and the gap are O(1) formulas
    # evaluated at the same points, equal where in contact up to ~5 ulps: 1e-15 slack
    assert (pressure >= 0).all() and (u_n <= gap + 1e-15).all()
    assert pressure * (gap - u_n) == pytest.approx(0.0, abs=1e-15)
    inside = np.abs(s) < 0.4
    assert (pressure[inside] > 0).all() and (pressure[~inside] == 0).all()  # free boundary
    assert (gap - u_n)[np.abs(s) > 0.401].min() > 0


def test_free_boundary_side_traction_is_sigma_n():
    scene = get_scene("free-boundary")
    exact, (lam, mu) = scene.exact, scene.material.lame
    y = np.linspace(-1, 1, 11)
    for side in (-1.0, 1.0):
        x = np.array([np.full_like(y, side), y])
        s11, s22, s12 = stress_from_gradient(exact.gradient(x), lam, mu)
        assert scene.traction(x) == pytest.approx(np.array([s11 * side, s12 * side]), abs=1e-15)


def test_hertz_formulas_by_hand():
    # E = 1000, nu = 0.3: E* = 1000 / 0.91 = 1098.9; P = 2, R = 1:
    # b = sqrt(8 / (pi 1098.9)) = 0.048137, p0 = 4 / (pi b) = 26.450
    scene = get_scene("hertz")
    hertz = hertz_prediction(scene, 2.0)
    assert hertz["e_star"] == pytest.approx(1098.9011, rel=1e-6)
    assert hertz["half_width"] == pytest.approx(0.048137, rel=1e-4)
    assert hertz["peak_pressure"] == pytest.approx(26.450, rel=1e-4)

"""Friction laws as scene data, and the stick-slip scene's data against its exact solution."""

import numpy as np
import pytest

from formulations.elasticity import stress_from_gradient
from scenes import SceneError, get_scene
from scenes.friction import NO_FRICTION, friction_law

STEP = 1e-5


def test_the_laws_and_their_labels():
    assert friction_law() is NO_FRICTION and not NO_FRICTION.active
    assert friction_law("coulomb", mu=0.3).label == "coulomb(mu=0.3)"
    tresca = friction_law("tresca", slip_bound=2.0)
    assert tresca.label == "tresca"
    assert tresca.slip_bound(np.zeros((2, 3))) == pytest.approx([2.0, 2.0, 2.0], abs=0)


@pytest.mark.parametrize("kwargs, message", [
    (dict(friction="stribeck"), r"friction='stribeck' is not one of none, tresca, coulomb"),
    (dict(friction="coulomb"), r"mu=0.0 is not in \(0, 100\]"),
    (dict(friction="coulomb", mu=1e300), r"mu=1e\+300 is not in \(0, 100\]"),
    (dict(friction="coulomb", mu=-1.0), r"mu=-1.0 is not a finite number >= 0"),
    (dict(friction="tresca"), r"slip_bound=0.0 is not > 0"),
    (dict(mu=0.3), r"mu=0.3 needs friction='coulomb'"),
    (dict(friction="coulomb", mu=0.3, slip_bound=1.0), r"slip_bound=1.0 needs friction='tresca'"),
])
def test_a_bad_law_is_refused_naming_the_parameter(kwargs, message):
    with pytest.raises(SceneError, match=message):
        get_scene("paper", **kwargs)


def test_paper_keeps_its_frictionless_parameters_and_takes_a_law():
    # the frictionless scene's parameters (the key of its cached references) are unchanged
    assert "friction" not in get_scene("paper").parameters
    scene = get_scene("paper", friction="coulomb", mu=0.1)
    assert scene.friction.coefficient == 0.1 and scene.parameters["mu"] == 0.1


def stress_tensor(scene, x):
    lam, mu = scene.material.lame
    s11, s22, s12 = stress_from_gradient(scene.exact.gradient(x), lam, mu)
    return np.array([[s11, s12], [s12, s22]])


def test_stick_slip_gradient_and_body_force_by_finite_differences():
    scene = get_scene("stick-slip")
    exact = scene.exact
    rng = np.random.default_rng(3)
    x = rng.uniform(-0.95, 0.95, size=(2, 300))
    # f jumps at |x| = a (p'') and |x| = b (tau''', chi'')
    x = x[:, (np.abs(np.abs(x[0]) - 0.4) > 1e-3) & (np.abs(np.abs(x[0]) - 0.2) > 1e-3)]
    div = np.zeros_like(x)
    for j in (0, 1):
        e = np.zeros((2, 1))
        e[j] = STEP
        fd = (exact.displacement(x + e) - exact.displacement(x - e)) / (2 * STEP)
        # central differences of O(1e-2) smooth fields: truncation ~1e-10
        assert fd == pytest.approx(exact.gradient(x)[:, j], abs=1e-8)
        div += (stress_tensor(scene, x + e)[:, j] - stress_tensor(scene, x - e)[:, j]) / (2 * STEP)
    assert scene.body_force(x) == pytest.approx(-div, abs=1e-6 * np.abs(div).max())


def test_stick_slip_satisfies_the_contact_and_friction_laws_on_gamma_c():
    scene = get_scene("stick-slip")
    exact, mu_f = scene.exact, scene.parameters["mu"]
    s = np.linspace(-1, 1, 801)
    x = np.array([s, -np.ones_like(s)])
    sigma = stress_tensor(scene, x)
    u = exact.displacement(x)
    u_n, u_t = -u[1], u[0]  # n = (0, -1), t = (1, 0)
    pressure, shear = exact.pressure(s), exact.shear(s)
    # sigma n = (-sigma_xy, -sigma_yy): sigma_n = sigma_yy = -p, sigma_t = -sigma_xy
    assert -sigma[1, 1] == pytest.approx(pressure, abs=1e-15)
    assert -sigma[0, 1] == pytest.approx(shear, abs=1e-15)
    assert u_n == pytest.approx(np.minimum(u_n, scene.gap(x)), abs=1e-15)
    bound = mu_f * pressure  # Tresca's s, and Coulomb's mu |sigma_n|
    assert (np.abs(shear) <= bound + 1e-15).all()
    stick, slip = np.abs(s) < 0.2, (np.abs(s) > 0.2) & (np.abs(s) < 0.4)
    assert (u_t[stick] == 0).all() and (np.abs(shear[stick]) < bound[stick]).all()
    # slip: |sigma_t| = s and sigma_t opposes u_t
    assert np.abs(shear[slip]) == pytest.approx(bound[slip], rel=1e-14)
    assert (np.sign(u_t[slip]) == -np.sign(shear[slip])).all() and (u_t[slip] != 0).all()
    assert (pressure[np.abs(s) > 0.4] == 0).all() and (shear[np.abs(s) > 0.4] == 0).all()


def test_stick_slip_side_traction_is_sigma_n_and_the_top_is_clamped():
    scene = get_scene("stick-slip")
    y = np.linspace(-1, 1, 11)
    for side in (-1.0, 1.0):
        x = np.array([np.full_like(y, side), y])
        assert scene.traction(x) == pytest.approx(stress_tensor(scene, x)[:, 0] * side,
                                                  abs=1e-15)
    top = np.array([y, np.ones_like(y)])
    assert scene.exact.displacement(top) == pytest.approx(0.0, abs=1e-15)


def test_cattaneo_mindlin_stick_zone_at_hand_worked_numbers():
    from scenes.base import Material
    from scenes.hertz import cattaneo_mindlin
    # E = 1000, nu = 0, R = 1, P = 250 pi: b = sqrt(4 P R / (pi E*)) = 1, p0 = 2 P / (pi b) = 500;
    # Q = (3/4) mu P leaves c = b sqrt(1/4) = 1/2 and q(0) = mu p0 (1 - c/b) (Johnson, 7.1)
    P, mu = 250 * np.pi, 0.3
    predicted = cattaneo_mindlin(mu, -1e-3)(Material(1000.0, 0.0, "strain"), 1.0, P,
                                            0.75 * mu * P)
    assert predicted.stick_half_width == pytest.approx(0.5, rel=1e-14)
    assert predicted.shear(np.array([0.0]))[0] == pytest.approx(-mu * 500 * 0.5, rel=1e-14)

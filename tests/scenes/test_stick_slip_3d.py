"""The manufactured stick-slip-3d solution checked by numerical differentiation and against the
contact and friction laws on Gamma_C (scenes/stick_slip_3d.py)."""

import numpy as np
import pytest

from scenes import get_scene

H = 1e-5  # central differences: error O(H^2) ~ 1e-10 on these smooth pieces


def stress(scene, x):
    lam, mu = scene.material.lame
    grad = scene.exact.gradient(x)
    return mu * (grad + np.swapaxes(grad, 0, 1)) + lam * np.trace(grad) * np.eye(3)[:, :, None]


def test_gradient_and_body_force_by_finite_differences():
    scene = get_scene("stick-slip-3d")
    exact = scene.exact
    rng = np.random.default_rng(5)
    x = rng.uniform(-0.95, 0.95, (3, 300))
    r = np.hypot(x[0], x[1])
    # f jumps at r = a (p'') and r = b (tau''', chi'')
    x = x[:, (np.abs(r - 0.6) > 1e-3) & (np.abs(r - 0.3) > 1e-3)]
    x[:2, 0] = 0.0  # the axis, where e_r is undefined but every field is smooth
    div = 0.0
    for j in range(3):
        e = np.zeros((3, 1))
        e[j] = H
        fd = (exact.displacement(x + e) - exact.displacement(x - e)) / (2 * H)
        assert np.abs(fd - exact.gradient(x)[:, j]).max() < 1e-8
        div = div + (stress(scene, x + e) - stress(scene, x - e))[:, j] / (2 * H)
    # differences of stresses of size ~1e-2 over 2H: round-off ~1e-12 / 1e-5 relative to |div|
    assert np.abs(div + scene.body_force(x)).max() < 1e-6 * np.abs(div).max()


def test_contact_and_friction_laws_hold_on_gamma_c():
    scene = get_scene("stick-slip-3d")
    exact, mu_f = scene.exact, scene.parameters["mu"]
    rng = np.random.default_rng(6)
    b = np.vstack([rng.uniform(-1, 1, (2, 2000)), -np.ones(2000)])
    b[:2, 0] = 0.0
    r = np.hypot(b[0], b[1])
    sigma, u = stress(scene, b), exact.displacement(b)
    pressure, shear = exact.pressure(b[:2]), exact.shear(b[:2])
    # n = (0, 0, -1): sigma n = -(sigma_xz, sigma_yz, sigma_zz)
    assert np.abs(sigma[2, 2] + pressure).max() < 1e-15
    assert np.abs(-sigma[:2, 2] - shear[:2]).max() < 1e-15 and (shear[2] == 0).all()
    u_n, g = -u[2], scene.gap(b)
    assert np.all(u_n <= g + 1e-15) and np.abs((g - u_n)[pressure > 0]).max() < 1e-15
    size, bound = np.linalg.norm(shear, axis=0), mu_f * pressure
    assert np.all(size <= bound * (1 + 1e-14))
    stick, slip = r < 0.3, (r > 0.3) & (r < 0.6)
    assert (u[:2, stick] == 0).all() and (size[stick] < bound[stick]).all()
    # slip: |sigma_t| = s, sigma_t opposite to u_t
    assert size[slip] == pytest.approx(bound[slip], rel=1e-14)
    cosine = np.einsum("ij,ij->j", u[:2, slip], shear[:2, slip]) / (
        np.linalg.norm(u[:2, slip], axis=0) * size[slip])
    assert cosine == pytest.approx(-1.0, abs=1e-14)
    assert (pressure[r > 0.6] == 0).all() and (size[r > 0.6] == 0).all()


def test_sides_carry_sigma_n_and_the_top_is_clamped():
    scene = get_scene("stick-slip-3d")
    rng = np.random.default_rng(7)
    s = np.array([np.ones(50), rng.uniform(-1, 1, 50), rng.uniform(-1, 1, 50)])
    assert np.allclose(scene.traction(s), stress(scene, s)[:, 0], atol=1e-15)
    s = np.array([rng.uniform(-1, 1, 50), -np.ones(50), rng.uniform(-1, 1, 50)])
    assert np.allclose(scene.traction(s), -stress(scene, s)[:, 1], atol=1e-15)
    top = np.vstack([rng.uniform(-1, 1, (2, 50)), np.ones(50)])
    assert np.abs(scene.exact.displacement(top)).max() < 1e-15


def test_coulomb_and_tresca_share_the_solution_and_bad_widths_are_refused():
    from scenes.base import SceneError
    coulomb = get_scene("stick-slip-3d", friction="coulomb")
    assert coulomb.friction.kind == "coulomb" and coulomb.friction.coefficient == 0.3
    with pytest.raises(SceneError, match="stick_half_width"):
        get_scene("stick-slip-3d", stick_half_width=0.7)

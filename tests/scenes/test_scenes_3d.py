"""The 3D scenes: the manufactured free-boundary-3d solution checked by numerical
differentiation, Hertz's sphere formulas, and the scenes' own validation."""

import numpy as np
import pytest

from scenes import get_scene
from scenes.hertz_3d import hertz_sphere

H = 1e-5  # central differences: error O(H^2) ~ 1e-10 on these smooth pieces


def stress(scene, x):
    lam, mu = scene.material.lame
    grad = scene.exact.gradient(x)
    return mu * (grad + np.swapaxes(grad, 0, 1)) + lam * np.trace(grad) * np.eye(3)[:, :, None]


def test_free_boundary_3d_is_a_signorini_solution():
    scene = get_scene("free-boundary-3d")
    rng = np.random.default_rng(0)
    x = rng.uniform(-0.95, 0.95, (3, 200))
    x = x[:, np.abs(np.hypot(x[0], x[1]) - 0.4) > 1e-3]  # away from the jump of f at r = a
    exact = scene.exact
    for j in range(3):  # the gradient against differences of u
        e = np.zeros((3, 1))
        e[j] = H
        fd = (exact.displacement(x + e) - exact.displacement(x - e)) / (2 * H)
        assert np.abs(fd - exact.gradient(x)[:, j]).max() < 1e-8
    div = sum((stress(scene, x + H * np.eye(3)[:, j:j + 1]) - stress(scene, x - H * np.eye(3)[
        :, j:j + 1]))[:, j] / (2 * H) for j in range(3))
    assert np.abs(div + scene.body_force(x)).max() < 1e-7 * np.abs(div).max()
    # the bottom: sigma_nn = -p, no shear, u_n = g inside the disc and u_n <= g outside
    b = np.vstack([rng.uniform(-1, 1, (2, 400)), -np.ones(400)])
    sigma = stress(scene, b)
    p = exact.pressure(b[:2])
    assert np.abs(sigma[2, 2] + p).max() < 1e-14 and np.abs(sigma[:2, 2]).max() < 1e-14
    u_n, g = -exact.displacement(b)[2], scene.gap(b)
    assert np.all(u_n <= g + 1e-15)
    assert np.abs((g - u_n)[p > 0]).max() < 1e-15
    # the sides: the traction is sigma n
    s = np.array([np.ones(50), rng.uniform(-1, 1, 50), rng.uniform(-1, 1, 50)])
    assert np.allclose(scene.traction(s), stress(scene, s)[:, 0], atol=1e-15)


def test_hertz_sphere_formulas():
    # a^3 = 3 P R / (4 E*) and p0 = 3 P / (2 pi a^2) (Johnson, Contact Mechanics, 4.2), at
    # numbers worked by hand: E = 1000, nu = 0, R = 1, P = 4000/3 -> a = 1, p0 = 2000/pi
    contact = hertz_sphere(1000.0, 0.0, 1.0, 4000.0 / 3.0)
    assert contact.half_width == pytest.approx(1.0, rel=1e-14)
    assert contact.peak_pressure == pytest.approx(2000.0 / np.pi, rel=1e-14)


@pytest.mark.parametrize("name", ["free-boundary-3d", "hertz-3d", "paper-3d"])
def test_3d_scenes_are_3d_and_their_contact_boundary_is_the_bottom_face(name):
    scene = get_scene(name)
    assert scene.dim == 3 and "3d" in scene.tags
    area = scene.facet_measures(scene.contact_facets()).sum()
    side = np.ptp(scene.mesh.p[0])
    assert area == pytest.approx(side**2, rel=1e-13)


def test_plane_stress_is_refused_in_3d():
    from scenes.base import Material, Scene, SceneError
    base = get_scene("paper-3d")
    with pytest.raises(SceneError, match="material.plane"):
        Scene(name="x", description="", mesh=base.mesh, material=Material(1.0, 0.3, "stress"),
              is_dirichlet=base.is_dirichlet, is_contact=base.is_contact, gap=base.gap,
              contact_coordinate=base.contact_coordinate)

"""``free-boundary-3d``: an exact 3D Signorini solution whose contact zone, a disc, ends inside
Gamma_C (docs/theory.md, section 14.2).

Omega = (-1, 1)^3 clamped on top (z = 1), Gamma_C the bottom face (outer normal (0, 0, -1)), the
sides loaded by the exact traction. The 2D scene ``free-boundary`` turned about the z axis:
u = (0, 0, w) with r^2 = x^2 + y^2 and

    w(x, y, z) = c (1 - z) / 2 + phi(z) q(r),   phi(z) = (z + 1) (1 - z)^2 / 4,
    q(r) = c / 2 - p(r) / (lambda + 2 mu),      p(r) = P0 (1 - (r / a)^2)_+^2,

so w = 0 on the top, w = c on the bottom (u_n = -c), sigma_xz = mu phi q_x = 0 and
sigma_yz = mu phi q_y = 0 there (phi(-1) = 0) and sigma_zz(x, y, -1) = (lambda + 2 mu)(-c/2 + q)
= -p(r): the pressure is p >= 0, positive exactly on the disc r < a. The gap is
g = -c + k (r - a)_+^2, so u_n = g where p > 0 and u_n < g elsewhere. With sigma = lambda w_z I
+ mu (grad u + grad u'), the body force f = -div sigma(u) is

    f = -( (lambda + mu) phi' q_x, (lambda + mu) phi' q_y, mu phi Lap q + (lambda + 2 mu) phi'' q ),

Lap p = -8 P0 (1 - 2 (r / a)^2) / a^2 inside the disc, 0 outside (a jump at r = a, as in 2D).
Manufactured: a test differentiates u numerically against every formula here.
"""

from __future__ import annotations

import numpy as np

from scenes.base import ExactSolution, Material, Scene, SceneError, is_integer
from scenes.budget import tensor_mesh
from scenes.free_boundary import _phi
from scenes.registry import register_scene

_TOL = 1e-10


def side_normals(x: np.ndarray) -> np.ndarray:
    """Outer normals (3, ...) of the cube's sides x = +-1 and y = +-1 at points on them."""
    on_x = np.abs(x[0]) >= np.abs(x[1])
    zero = 0.0 * x[0]
    return np.array([np.where(on_x, np.sign(x[0]), zero),
                     np.where(on_x, zero, np.sign(x[1])), zero])


@register_scene("free-boundary-3d", "exact 3D Signorini solution on the cube (-1,1)^3 with the "
                                    "contact zone a disc r < a inside Gamma_C (manufactured)",
                tags=("exact", "3d"), dim=3)
def free_boundary_3d(young_modulus: float = 1.0, poisson_ratio: float = 0.3, push: float = 0.01,
                     half_width: float = 0.4, gap_curvature: float = 0.1,
                     initial_divisions: int = 4) -> Scene:
    if not (0 < half_width < 1):
        raise SceneError(f"half_width={half_width!r} is not in (0, 1)")
    if not (is_integer(initial_divisions) and initial_divisions >= 2):
        raise SceneError(f"initial_divisions={initial_divisions!r} is not an integer >= 2")
    material = Material(young_modulus, poisson_ratio, "strain")
    lam, mu = material.lame
    stiff = lam + 2 * mu
    c, a, k = push, half_width, gap_curvature
    P0 = c * stiff  # q(0) = -c/2, as in 2D

    def q(x):
        """q, q_x, q_y and Lap q at points x."""
        s = (x[0] ** 2 + x[1] ** 2) / a**2
        inside = s < 1
        r = np.clip(1 - s, 0.0, None)
        dp = -4 * P0 * r / a**2 * inside  # dp/dx = dp * x, dp/dy = dp * y
        lap = -8 * P0 * (1 - 2 * s) / a**2 * inside
        return c / 2 - P0 * r**2 / stiff, -dp * x[0] / stiff, -dp * x[1] / stiff, -lap / stiff

    def displacement(x):
        zero = 0.0 * x[0]
        return np.array([zero, zero, c * (1 - x[2]) / 2 + _phi(x[2])[0] * q(x)[0]])

    def gradient(x):
        phi, dphi, _ = _phi(x[2])
        q0, qx, qy, _ = q(x)
        zero = 0.0 * x[0]
        return np.array([[zero, zero, zero], [zero, zero, zero],
                         [phi * qx, phi * qy, -c / 2 + dphi * q0]])

    def body_force(x):
        phi, dphi, ddphi = _phi(x[2])
        q0, qx, qy, lap = q(x)
        return -np.array([(lam + mu) * dphi * qx, (lam + mu) * dphi * qy,
                          mu * phi * lap + stiff * ddphi * q0])

    def traction(x):  # sigma(u) n on the sides
        grad, n = gradient(x), side_normals(x)
        sigma = mu * (grad + np.swapaxes(grad, 0, 1)) + lam * grad[2, 2] * np.eye(3).reshape(
            (3, 3) + (1,) * (x.ndim - 1))
        return np.einsum("ij...,j...->i...", sigma, n)

    def pressure(s):
        s = np.asarray(s, dtype=float)
        return P0 * np.clip(1 - (s[0] ** 2 + s[1] ** 2) / a**2, 0.0, None) ** 2

    grid = np.linspace(-1.0, 1.0, int(initial_divisions) + 1)
    return Scene(
        name="free-boundary-3d",
        description="manufactured exact 3D Signorini solution, contact zone the disc r < a",
        mesh=tensor_mesh(grid, grid, grid), material=material,
        is_dirichlet=lambda x: np.abs(x[2] - 1.0) < _TOL,
        is_contact=lambda x: np.abs(x[2] + 1.0) < _TOL,
        gap=lambda x: -c + k * np.clip(np.hypot(x[0], x[1]) - a, 0.0, None) ** 2,
        contact_coordinate=lambda x: np.asarray(x)[:2], body_force=body_force,
        traction=traction,
        parameters={"young_modulus": young_modulus, "poisson_ratio": poisson_ratio,
                    "push": push, "half_width": half_width, "gap_curvature": gap_curvature,
                    "initial_divisions": initial_divisions},
        tags=("exact", "3d"),
        exact=ExactSolution(displacement=displacement, gradient=gradient, pressure=pressure,
                            contact_zone=(-a, a), source="manufactured (module docstring)"),
    )

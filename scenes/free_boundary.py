"""``free-boundary``: an exact elastic Signorini solution whose contact zone ends inside Gamma_C.

Omega = (-1, 1)^2 clamped on top, Gamma_C the bottom edge (outer normal (0, -1)), the sides loaded
by the exact traction. The displacement is u = (0, v) with

    v(x, y) = c (1 - y) / 2 + phi(y) q(x),   phi(y) = (y + 1) (1 - y)^2 / 4,
    q(x) = c / 2 - p(x) / (lambda + 2 mu),   p(x) = P0 (1 - (x / a)^2)_+^2,

so v = 0 on the top, v = c on the bottom (u_n = -c), sigma_xy = mu phi q' = 0 on the bottom and
sigma_yy(x, -1) = (lambda + 2 mu)(-c/2 + q) = -p(x): the contact pressure is p >= 0, positive
exactly on |x| < a. The gap is g = -c + k (|x| - a)_+^2: u_n = g where p > 0 and u_n < g where
p = 0, so u satisfies the Signorini conditions with a free boundary at x = -a and x = a (no strict
complementarity there: both p and g - u_n vanish). The body force f = -div sigma(u) is

    f = ( -(lambda + mu) phi' q',  -mu phi q'' - (lambda + 2 mu) phi'' q ),

(phi' = (1 - y)(-1 - 3 y) / 4, phi'' = (3 y - 1) / 2), discontinuous at |x| = a where p'' jumps.
A manufactured solution: the data are made to fit u, so every formula here is checked by a test
that differentiates u numerically.
"""

from __future__ import annotations

import numpy as np

from scenes.base import ExactSolution, Material, Scene
from scenes.budget import tensor_mesh
from scenes.registry import register_scene

_TOL = 1e-10


def _phi(y):
    return (y + 1) * (1 - y) ** 2 / 4, (1 - y) * (-1 - 3 * y) / 4, (3 * y - 1) / 2


@register_scene("free-boundary", "exact elastic Signorini solution on the unit square with the "
                                 "contact zone |x| < a ending inside Gamma_C (manufactured)",
                tags=("exact",), dim=2)
def free_boundary(young_modulus: float = 1.0, poisson_ratio: float = 0.3, plane: str = "strain",
                  push: float = 0.01, half_width: float = 0.4, gap_curvature: float = 0.1,
                  initial_divisions: int = 4, align_jump: int = 0) -> Scene:
    material = Material(young_modulus, poisson_ratio, plane)
    lam, mu = material.lame
    stiff = lam + 2 * mu
    c, a, k = push, half_width, gap_curvature
    P0 = c * stiff  # q(0) = -c/2: the pressure term is as large as the push term

    def p(x):
        r = np.clip(1 - (x / a) ** 2, 0.0, None)
        inside = np.abs(x) < a
        return (P0 * r**2, P0 * 2 * r * (-2 * x / a**2) * inside,
                P0 * (-4 / a**2 + 12 * x**2 / a**4) * inside)

    def q(x):
        p0, p1, p2 = p(x)
        return c / 2 - p0 / stiff, -p1 / stiff, -p2 / stiff

    def displacement(x):
        phi = _phi(x[1])[0]
        return np.array([0.0 * x[0], c * (1 - x[1]) / 2 + phi * q(x[0])[0]])

    def gradient(x):
        phi, dphi, _ = _phi(x[1])
        q0, q1, _ = q(x[0])
        zero = 0.0 * x[0]
        return np.array([[zero, zero], [phi * q1, -c / 2 + dphi * q0]])

    def body_force(x):
        phi, dphi, ddphi = _phi(x[1])
        q0, q1, q2 = q(x[0])
        return np.array([-(lam + mu) * dphi * q1, -mu * phi * q2 - stiff * ddphi * q0])

    def traction(x):  # sigma(u) n on the sides x = +-1, n = (sign x, 0)
        grad = gradient(x)
        eyy, exy = grad[1, 1], 0.5 * grad[1, 0]
        return np.array([lam * eyy * np.sign(x[0]), 2 * mu * exy * np.sign(x[0])])

    if not (0 < a < 1):
        raise ValueError(f"half_width={a!r} is not in (0, 1)")
    grid = np.linspace(-1.0, 1.0, initial_divisions + 1)
    if align_jump not in (0, 1):
        raise ValueError(f"align_jump={align_jump!r} is not 0 or 1")
    x_grid = aligned(grid, (-a, a)) if align_jump else grid
    return Scene(
        name="free-boundary",
        description="manufactured exact Signorini solution, contact zone |x| < a inside Gamma_C",
        mesh=tensor_mesh(x_grid, grid), material=material,
        is_dirichlet=lambda x: np.abs(x[1] - 1.0) < _TOL,
        is_contact=lambda x: np.abs(x[1] + 1.0) < _TOL,
        gap=lambda x: -c + k * np.clip(np.abs(x[0]) - a, 0.0, None) ** 2,
        contact_coordinate=lambda x: x[0], body_force=body_force, traction=traction,
        parameters={"young_modulus": young_modulus, "poisson_ratio": poisson_ratio,
                    "plane": plane, "push": push, "half_width": half_width,
                    "gap_curvature": gap_curvature, "initial_divisions": initial_divisions,
                    "align_jump": align_jump},
        tags=("exact",),
        exact=ExactSolution(displacement=displacement, gradient=gradient,
                            pressure=lambda s: p(np.asarray(s, dtype=float))[0],
                            contact_zone=(-a, a), source="manufactured (module docstring)"),
        load_jump=lambda x: np.abs(x[0]) - a,
    )


def aligned(grid: np.ndarray, lines: tuple[float, ...]) -> np.ndarray:
    """``grid`` with its interior point nearest to each of ``lines`` moved onto it, so that the
    lines where the body force jumps are mesh lines on every refinement (bisection keeps them):
    f is then smooth on every element, and its oscillation is that of a smooth function
    (docs/theory.md, 13.2)."""
    out = grid.copy()
    for line in lines:
        inner = np.arange(1, len(out) - 1)
        nearest = inner[np.abs(out[inner] - line).argmin()]
        out[nearest] = line
    if np.any(np.diff(out) <= 0) or not all(np.isin(lines, out)):
        raise ValueError(f"initial_divisions={len(grid) - 1}: too few grid lines to align "
                         f"with x = {', '.join(f'{v:g}' for v in lines)}")
    return out


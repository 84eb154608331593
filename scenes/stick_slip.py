"""``stick-slip``: an exact elastic contact solution with friction whose contact zone holds a
stick zone and two slip zones, all ending inside Gamma_C (manufactured; docs/theory.md, 17.4).

Omega = (-1, 1)^2 clamped on top, Gamma_C the bottom edge (n = (0, -1), t = (1, 0)), the sides
loaded by the exact traction. With the pressure p(x) = P0 (1 - (x / a)^2)_+^2 of
``free-boundary``, a friction coefficient mu_f and the shear modulus mu, the displacement is

    U = psi(y) tau(x) + phi(y) omega(x),   v = c (1 - y) / 2 + phi(y) q(x),
    psi = (1 - y)^2 (2 + y) / 4,  phi = (y + 1) (1 - y)^2 / 4,
    tau = d sign(x) (|x| - b)_+^3,  omega = (mu_f / mu) p chi,
    chi(x) = (3 r - r^3) / 2 for r = x / b in (-1, 1), sign(x) beyond,
    q = c / 2 - (p + lambda tau') / (lambda + 2 mu).

On the bottom (psi = 1, psi' = 0, phi = 0, phi' = 1): u_t = tau, u_n = -c,
sigma_yy = -p and sigma_xy = mu omega, so the shear traction is sigma_t = -sigma_xy =
-mu_f p chi. Hence: |x| < b sticks (u_t = 0, |sigma_t| < mu_f p); b < |x| < a slips
(sigma_t = -mu_f p u_t / |u_t|); |x| > a is separated (p = 0, sigma_t = 0, u_n < g). The gap is
free-boundary's g = -c + k (|x| - a)_+^2. The law: ``tresca`` with slip bound s = mu_f p (the
given function), or ``coulomb`` with mu = mu_f: the same u solves both.

tau and chi are as rough as f allows (f holds tau''' and chi'', both jump at |x| = b, as f
jumps at |x| = a): beyond the stick zone's end the slip grows like (|x| - b)^3 and the
traction's distance to its bound like (|x| - b)^2, so that the end is as sharp as it can be.
"""

from __future__ import annotations

import numpy as np

from scenes.base import ExactSolution, Material, Scene, SceneError
from scenes.budget import tensor_mesh
from scenes.friction import MU_MAX, FrictionLaw
from scenes.registry import register_scene

_TOL = 1e-10


def _psi(y):
    return (1 - y) ** 2 * (2 + y) / 4, -3 * (1 - y**2) / 4, 3 * y / 2


def _phi(y):
    return (y + 1) * (1 - y) ** 2 / 4, (1 - y) * (-1 - 3 * y) / 4, (3 * y - 1) / 2


def _chi(x, b):
    r = x / b
    inside = np.abs(r) < 1
    rc = np.clip(r, -1.0, 1.0)
    value = np.where(inside, (3 * rc - rc**3) / 2, np.sign(r))
    return value, 3 * (1 - rc**2) / (2 * b) * inside, -3 * rc / b**2 * inside


def check_zones(half_width: float, stick_half_width: float, friction: str, mu: float) -> None:
    """The stick and slip zones inside Gamma_C, and a law the exact solution solves."""
    if not (0 < stick_half_width < half_width < 1):
        raise SceneError(f"stick_half_width={stick_half_width!r}, half_width={half_width!r}: "
                         "need 0 < stick_half_width < half_width < 1")
    if friction not in ("tresca", "coulomb") or not 0 < mu <= MU_MAX:
        raise SceneError(f"friction={friction!r}, mu={mu!r}: need 'tresca' or 'coulomb' and "
                         f"mu in (0, {MU_MAX:g}] (measured friction coefficients lie below "
                         "about 2)")


def profiles(material: Material, push: float, half_width: float, stick_half_width: float,
             mu_f: float, slide: float):
    """The x-profiles (value, first, second, third derivative as needed): p, tau, omega, q."""
    lam, mu = material.lame
    stiff = lam + 2 * mu
    c, a, b, P0 = push, half_width, stick_half_width, push * stiff

    def p(x):
        r = np.clip(1 - (x / a) ** 2, 0.0, None)
        inside = np.abs(x) < a
        return (P0 * r**2, P0 * 2 * r * (-2 * x / a**2) * inside,
                P0 * (-4 / a**2 + 12 * x**2 / a**4) * inside)

    def tau(x):
        e = np.clip(np.abs(x) - b, 0.0, None)
        s = np.sign(x)
        return slide * s * e**3, 3 * slide * e**2, 6 * slide * s * e, 6 * slide * (e > 0)

    def omega(x):
        (p0, p1, p2), (c0, c1, c2) = p(x), _chi(x, b)
        k = mu_f / mu
        return k * p0 * c0, k * (p1 * c0 + p0 * c1), k * (p2 * c0 + 2 * p1 * c1 + p0 * c2)

    def q(x):
        (p0, p1, p2), (_, t1, t2, t3) = p(x), tau(x)
        return (c / 2 - (p0 + lam * t1) / stiff, -(p1 + lam * t2) / stiff,
                -(p2 + lam * t3) / stiff)

    return p, tau, omega, q


def fields(material: Material, push: float, tau, omega, q):
    """(displacement, gradient, body force, side traction) of u from its x-profiles (module
    docstring)."""
    lam, shear = material.lame
    stiff, c = lam + 2 * shear, push

    def gradient(x):
        (s0, s1, _), (f0, f1, _) = _psi(x[1]), _phi(x[1])
        t, w, q_ = tau(x[0]), omega(x[0]), q(x[0])
        return np.array([[s0 * t[1] + f0 * w[1], s1 * t[0] + f1 * w[0]],
                         [f0 * q_[1], -c / 2 + f1 * q_[0]]])

    def body_force(x):  # f = -div sigma(u) (module docstring)
        (s0, s1, s2), (f0, f1, f2) = _psi(x[1]), _phi(x[1])
        t, w, q_ = tau(x[0]), omega(x[0]), q(x[0])
        Uxx, Uyy, Uxy = s0 * t[2] + f0 * w[2], s2 * t[0] + f2 * w[0], s1 * t[1] + f1 * w[1]
        vxx, vyy, vxy = f0 * q_[2], f2 * q_[0], f1 * q_[1]
        return np.array([-(stiff * Uxx + (lam + shear) * vxy + shear * Uyy),
                         -((lam + shear) * Uxy + shear * vxx + stiff * vyy)])

    def traction(x):  # sigma(u) n on the sides x = +-1, n = (sign x, 0)
        g = gradient(x)
        div = g[0, 0] + g[1, 1]
        side = np.sign(x[0])
        return np.array([(lam * div + 2 * shear * g[0, 0]) * side,
                         shear * (g[0, 1] + g[1, 0]) * side])

    def displacement(x):
        t, w, q_ = tau(x[0]), omega(x[0]), q(x[0])
        return np.array([_psi(x[1])[0] * t[0] + _phi(x[1])[0] * w[0],
                         c * (1 - x[1]) / 2 + _phi(x[1])[0] * q_[0]])

    return displacement, gradient, body_force, traction


@register_scene("stick-slip", "exact elastic contact with friction on the unit square: stick "
                              "zone |x| < b and slip zones b < |x| < a inside Gamma_C "
                              "(manufactured; tresca or coulomb)", tags=("exact",), dim=2)
def stick_slip(young_modulus: float = 1.0, poisson_ratio: float = 0.3, plane: str = "strain",
               push: float = 0.01, half_width: float = 0.4, stick_half_width: float = 0.2,
               gap_curvature: float = 0.1, mu: float = 0.3, slide: float = 0.05,
               friction: str = "tresca", initial_divisions: int = 4) -> Scene:
    check_zones(half_width, stick_half_width, friction, mu)
    material = Material(young_modulus, poisson_ratio, plane)
    c, a, k = push, half_width, gap_curvature
    p, tau, omega, q = profiles(material, push, half_width, stick_half_width, mu, slide)

    displacement, gradient, body_force, traction = fields(material, push, tau, omega, q)

    def shear_traction(s):  # sigma_t = -mu_f p chi along Gamma_C
        s = np.asarray(s, dtype=float)
        return -mu * p(s)[0] * _chi(s, stick_half_width)[0]

    law = (FrictionLaw("coulomb", coefficient=float(mu)) if friction == "coulomb"
           else FrictionLaw("tresca", slip_bound=lambda x: mu * p(x[0])[0]))
    grid = np.linspace(-1.0, 1.0, initial_divisions + 1)
    return Scene(
        name="stick-slip",
        description="manufactured exact contact with friction: stick |x| < b, slip "
                    "b < |x| < a, separation |x| > a on Gamma_C",
        mesh=tensor_mesh(grid, grid), material=material,
        is_dirichlet=lambda x: np.abs(x[1] - 1.0) < _TOL,
        is_contact=lambda x: np.abs(x[1] + 1.0) < _TOL,
        gap=lambda x: -c + k * np.clip(np.abs(x[0]) - a, 0.0, None) ** 2,
        contact_coordinate=lambda x: x[0], body_force=body_force, traction=traction,
        parameters={"young_modulus": young_modulus, "poisson_ratio": poisson_ratio,
                    "plane": plane, "push": push, "half_width": half_width,
                    "stick_half_width": stick_half_width, "gap_curvature": gap_curvature,
                    "mu": mu, "slide": slide, "friction": friction,
                    "initial_divisions": initial_divisions},
        tags=("exact",),
        exact=ExactSolution(displacement=displacement, gradient=gradient,
                            pressure=lambda s: p(np.asarray(s, dtype=float))[0],
                            contact_zone=(-a, a), source="manufactured (module docstring)",
                            shear=shear_traction,
                            stick_zone=(-stick_half_width, stick_half_width)),
        friction=law,
        # f jumps at |x| = a and |x| = b: phi changes sign across each
        load_jump=lambda x: (np.abs(x[0]) - a) * (np.abs(x[0]) - stick_half_width),
    )

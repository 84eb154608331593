"""``stick-slip-3d``: an exact 3D elastic contact solution with friction whose contact zone, a
disc r < a, holds a stick disc r < b and a slip ring b < r < a, all inside Gamma_C
(manufactured; docs/theory.md, 17.4): ``stick-slip`` turned about the z axis.

Omega = (-1, 1)^3 clamped on top (z = 1), Gamma_C the bottom face (n = (0, 0, -1)), the sides
loaded by the exact traction. With X = (x, y), r = |X|, e_r = X / r and the 2D scene's profiles
p (the pressure), chi and tau (docs of ``stick_slip``), the displacement is u = (U, w),

    U = psi(z) T(X) + phi(z) W(X),   w = c (1 - z) / 2 + phi(z) Q(X),
    T = tau(r) e_r,  W = (mu_f / mu) p(r) chi(r) e_r,
    Q = c / 2 - (p + lambda div T) / (lambda + 2 mu).

On the bottom (psi = 1, psi' = 0, phi = 0, phi' = 1): u_t = T, u_n = -c, sigma_zz = -p and
(sigma_xz, sigma_yz) = mu W, so the shear traction is sigma_t = -mu_f p chi e_r: the disc
r < b sticks, the ring b < r < a slips outwards against the bound mu_f p, and r > a is
separated (the gap is free-boundary-3d's g = -c + k (r - a)_+^2). The law: ``tresca`` with
s = mu_f p, or ``coulomb`` with mu = mu_f: the same u solves both. The default zones (a = 0.6,
b = 0.3) are wider than the 2D scene's, so that a 3D mesh of 1e4 DOFs has some 20 nodes in the
stick disc and 50 in the slip ring, and the slip amplitude d = 0.01 is smaller: T grows like
r^3 beyond the contact zone, and at d = 0.05 its error outweighed the rest (energy error 1.7e-2
against 4.7e-3 at 13 872 DOFs, vi P1).

Every radial field is F = h(r) X, so that grad F = h I + (h'/r) X X', div F = 2 h + r h' and,
F being a gradient, Lap F = grad div F = (3 h'/r + h'') X; chi(r) / r is a polynomial inside the
stick disc, so nothing is singular at r = 0. Manufactured: a test differentiates u numerically
against every formula here.
"""

from __future__ import annotations

import numpy as np

from scenes.base import ExactSolution, Material, Scene, SceneError, is_integer
from scenes.budget import tensor_mesh
from scenes.free_boundary_3d import side_normals
from scenes.friction import FrictionLaw
from scenes.registry import register_scene
from scenes.stick_slip import _phi, _psi, check_zones

_TOL = 1e-10


def pressure_profile(P0: float, a: float, r):
    """p, p'/r, p'' and Lap p = p'' + p'/r of p = P0 (1 - (r/a)^2)_+^2."""
    s = r**2 / a**2
    inside = s < 1
    one = np.clip(1 - s, 0.0, None)
    return (P0 * one**2, -4 * P0 * one / a**2 * inside, -4 * P0 * (1 - 3 * s) / a**2 * inside,
            -8 * P0 * (1 - 2 * s) / a**2 * inside)


def stick_field(P0: float, a: float, b: float, k: float, r):
    """h, h'/r, h'' of W = h X, h = k p chi / r (chi / r = (3/b - r^2/b^3) / 2 inside r < b,
    1 / r beyond)."""
    p, dp_r, ddp, _ = pressure_profile(P0, a, r)
    inside = r < b
    rs = np.where(inside, b, r)  # keeps 1 / r away from 0 where the polynomial branch holds
    g = np.where(inside, (3 / b - r**2 / b**3) / 2, 1 / rs)
    dg_r = np.where(inside, -1 / b**3, -1 / rs**3)  # g' / r
    ddg = np.where(inside, -1 / b**3, 2 / rs**3)
    rdg = r**2 * dg_r  # r g'
    return k * p * g, k * (dp_r * g + p * dg_r), k * (ddp * g + 2 * dp_r * rdg + p * ddg)


def slip_field(d: float, b: float, r):
    """h, h'/r, h'', h''' of T = h X, h = d (r - b)_+^3 / r (zero inside the stick disc)."""
    e = np.clip(r - b, 0.0, None)
    rs = np.maximum(r, b)
    out = e > 0
    return (d * e**3 / rs, d * (3 * e**2 / rs - e**3 / rs**2) / rs,
            d * (6 * e / rs - 6 * e**2 / rs**2 + 2 * e**3 / rs**3),
            d * (6 * out / rs - 18 * e / rs**2 + 18 * e**2 / rs**3 - 6 * e**3 / rs**4))


def profiles(material: Material, push: float, a: float, b: float, mu_f: float, d: float):
    """A function of X returning the radial quantities the fields need (``fields``)."""
    lam, mu = material.lame
    stiff = lam + 2 * mu
    P0 = push * stiff

    def at(X):
        r = np.hypot(X[0], X[1])
        p, dp_r, _, lap_p = pressure_profile(P0, a, r)
        hT, dT, ddT, dddT = slip_field(d, b, r)
        hW, dW, ddW = stick_field(P0, a, b, mu_f / mu, r)
        div_T, div_W = 2 * hT + r**2 * dT, 2 * hW + r**2 * dW
        grad_div_T, grad_div_W = 3 * dT + ddT, 3 * dW + ddW  # times X
        lap_div_T = 5 * ddT + r * dddT + 3 * dT
        Q = push / 2 - (p + lam * div_T) / stiff
        dQ = -(dp_r + lam * grad_div_T) / stiff  # Q' / r: grad Q = dQ X
        lap_Q = -(lap_p + lam * lap_div_T) / stiff
        return dict(p=p, hT=hT, dT=dT, hW=hW, dW=dW, div_T=div_T, div_W=div_W,
                    grad_div_T=grad_div_T, grad_div_W=grad_div_W, Q=Q, dQ=dQ, lap_Q=lap_Q)

    return at


def radial_gradient(h, dh_r, X):
    """grad (h X) = h I + (h'/r) X X' (2, 2, ...)."""
    eye = np.eye(2).reshape((2, 2) + (1,) * (X.ndim - 1))
    return h * eye + dh_r * np.einsum("i...,j...->ij...", X, X)


def fields(material: Material, push: float, at):
    """(displacement, gradient, body force, side traction) of u (module docstring)."""
    lam, mu = material.lame

    def gradient(x):
        X, (s0, s1, _), (f0, f1, _) = x[:2], _psi(x[2]), _phi(x[2])
        v = at(X)
        plane = (s0 * radial_gradient(v["hT"], v["dT"], X)
                 + f0 * radial_gradient(v["hW"], v["dW"], X))
        vertical = s1 * v["hT"] * X + f1 * v["hW"] * X
        top = np.concatenate([plane, vertical[:, None]], axis=1)
        bottom = np.concatenate([f0 * v["dQ"] * X, (-push / 2 + f1 * v["Q"])[None]])
        return np.concatenate([top, bottom[None]], axis=0)

    def body_force(x):  # f = -(mu Lap u + (lambda + mu) grad div u)
        X, (s0, _, s2), (f0, f1, f2) = x[:2], _psi(x[2]), _phi(x[2])
        v = at(X)
        lap_U = (s0 * v["grad_div_T"] + s2 * v["hT"] + f0 * v["grad_div_W"] + f2 * v["hW"]) * X
        grad_div_U = (s0 * v["grad_div_T"] + f0 * v["grad_div_W"] + f1 * v["dQ"]) * X
        lap_w = f2 * v["Q"] + f0 * v["lap_Q"]
        dz_div = _psi(x[2])[1] * v["div_T"] + f1 * v["div_W"] + f2 * v["Q"]
        return -np.concatenate([mu * lap_U + (lam + mu) * grad_div_U,
                                (mu * lap_w + (lam + mu) * dz_div)[None]])

    def traction(x):  # sigma(u) n on the sides
        grad, n = gradient(x), side_normals(x)
        trace = np.einsum("ii...->...", grad)
        sigma = mu * (grad + np.swapaxes(grad, 0, 1)) + lam * trace * np.eye(3).reshape(
            (3, 3) + (1,) * (x.ndim - 1))
        return np.einsum("ij...,j...->i...", sigma, n)

    def displacement(x):
        X, v = x[:2], at(x[:2])
        U = (_psi(x[2])[0] * v["hT"] + _phi(x[2])[0] * v["hW"]) * X
        return np.concatenate([U, (push * (1 - x[2]) / 2 + _phi(x[2])[0] * v["Q"])[None]])

    return displacement, gradient, body_force, traction


@register_scene("stick-slip-3d", "exact 3D elastic contact with friction on the cube (-1,1)^3: "
                                 "stick disc r < b and slip ring b < r < a inside Gamma_C "
                                 "(manufactured; tresca or coulomb)", tags=("exact", "3d"),
                dim=3)
def stick_slip_3d(young_modulus: float = 1.0, poisson_ratio: float = 0.3, push: float = 0.01,
                  half_width: float = 0.6, stick_half_width: float = 0.3,
                  gap_curvature: float = 0.1, mu: float = 0.3, slide: float = 0.01,
                  friction: str = "tresca", initial_divisions: int = 4) -> Scene:
    check_zones(half_width, stick_half_width, friction, mu)
    if not (is_integer(initial_divisions) and initial_divisions >= 2):
        raise SceneError(f"initial_divisions={initial_divisions!r} is not an integer >= 2")
    material = Material(young_modulus, poisson_ratio, "strain")
    c, a, b, k = push, half_width, stick_half_width, gap_curvature
    at = profiles(material, push, a, b, mu, slide)
    displacement, gradient, body_force, traction = fields(material, push, at)

    def pressure(s):
        return at(np.asarray(s, dtype=float))["p"]

    def shear_traction(s):  # sigma_t = -mu W = -mu_f p chi e_r, as a 3-vector
        s = np.asarray(s, dtype=float)
        v = at(s)
        planar = -material.lame[1] * v["hW"] * s
        return np.concatenate([planar, np.zeros_like(planar[:1])])

    law = (FrictionLaw("coulomb", coefficient=float(mu)) if friction == "coulomb"
           else FrictionLaw("tresca", slip_bound=lambda x: mu * pressure(np.asarray(x)[:2])))
    grid = np.linspace(-1.0, 1.0, int(initial_divisions) + 1)
    return Scene(
        name="stick-slip-3d",
        description="manufactured exact 3D contact with friction: stick r < b, slip "
                    "b < r < a, separation r > a on Gamma_C",
        mesh=tensor_mesh(grid, grid, grid), material=material,
        is_dirichlet=lambda x: np.abs(x[2] - 1.0) < _TOL,
        is_contact=lambda x: np.abs(x[2] + 1.0) < _TOL,
        gap=lambda x: -c + k * np.clip(np.hypot(x[0], x[1]) - a, 0.0, None) ** 2,
        contact_coordinate=lambda x: np.asarray(x)[:2], body_force=body_force,
        traction=traction,
        parameters={"young_modulus": young_modulus, "poisson_ratio": poisson_ratio,
                    "push": push, "half_width": half_width, "stick_half_width": b,
                    "gap_curvature": gap_curvature, "mu": mu, "slide": slide,
                    "friction": friction, "initial_divisions": initial_divisions},
        tags=("exact", "3d"),
        exact=ExactSolution(displacement=displacement, gradient=gradient, pressure=pressure,
                            contact_zone=(-a, a), source="manufactured (module docstring)",
                            shear=shear_traction, stick_zone=(-b, b)),
        friction=law,
    )

"""Singular exponents of plane elastic corners and the regularity they allow
(docs/theory.md, section 10).

Near a corner of opening angle omega the displacement behaves like r^lambda; the exponents
lambda are the values for which the wedge 0 < theta < omega carries a non-zero field
u = r^lambda f(theta) with its two sides' boundary conditions. In Kolosov-Muskhelishvili form,
phi = A z^lambda, psi = B z^lambda (A, B complex), with

    2 mu (u_x + i u_y) = kappa phi - z conj(phi') - conj(psi),
    sigma_tt + i sigma_rt = phi' + conj(phi') + exp(2 i theta) (conj(z) phi'' + psi'),

a clamped side asks u = 0 and a traction-free side sigma_tt + i sigma_rt = 0: four real
equations, linear in (Re A, Im A, Re B, Im B). Their 4 x 4 matrix is singular exactly at an
exponent; the smallest singular value is minimised over a grid of lambda and polished, which
finds double roots too (the crack's 1/2). Fields without stress (rigid motions) are left out.
Only real exponents are found: where a pair turns complex (clamped-free beyond about 3 pi / 4)
the smallest real part must come from elsewhere.
kappa = 3 - 4 nu in plane strain, (3 - nu) / (1 + nu) in plane stress.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize_scalar

SIDES = ("clamped", "free")
CONTACT_END_EXPONENT = 1.5  # u ~ r^(3/2) at the ends of a Signorini contact zone
GRID = 3000  # lambda samples on (0, upper]
ROOT = 1e-9  # smallest singular value (columns scaled to 1) that counts as singular


@dataclass(frozen=True)
class Corner:
    """A corner of a scene: its vertex, opening angle and the conditions on its two sides."""

    point: tuple[float, float]
    angle: float
    sides: tuple[str, str]

    def __post_init__(self):
        if not 0 < self.angle <= 2 * np.pi:
            raise ValueError(f"angle={self.angle!r} is not in (0, 2 pi]")
        for side in self.sides:
            if side not in SIDES:
                raise ValueError(f"sides={self.sides!r}: {side!r} is not one of "
                                 f"{', '.join(SIDES)}")


def kolosov(poisson_ratio: float, plane: str) -> float:
    if plane not in ("strain", "stress"):
        raise ValueError(f"plane={plane!r} is not 'strain' or 'stress'")
    nu = poisson_ratio
    return 3 - 4 * nu if plane == "strain" else (3 - nu) / (1 + nu)


def _side_rows(lam: float, theta: float, side: str, kappa: float) -> np.ndarray:
    """The two real equations (2, 4) of ``side`` at angle theta, one column per unit vector
    of (Re A, Im A, Re B, Im B)."""
    rows = []
    for coefficient in np.eye(4):
        if side == "clamped":
            value = _displacement(lam, coefficient, theta, kappa)
        else:
            value = _traction(lam, coefficient, theta)
        rows.append([value.real, value.imag])
    return np.array(rows).T


def _power(s: float, theta):
    """z^s on the unit circle, z = exp(i theta), on the branch continuous in theta (the
    wedge may open beyond pi)."""
    return np.exp(1j * s * np.asarray(theta))


def _potentials(lam: float, coefficient: np.ndarray, theta):
    A, B = coefficient[0] + 1j * coefficient[1], coefficient[2] + 1j * coefficient[3]
    return A, B, lam * A * _power(lam - 1, theta), lam * (lam - 1) * A * _power(lam - 2, theta)


def _displacement(lam, coefficient, theta, kappa):
    """2 mu (u_x + i u_y) at r = 1."""
    A, B, dphi, _ = _potentials(lam, coefficient, theta)
    z = _power(1.0, theta)
    return kappa * A * _power(lam, theta) - z * np.conj(dphi) - np.conj(B * _power(lam, theta))


def _traction(lam, coefficient, theta):
    """sigma_tt + i sigma_rt at r = 1."""
    A, B, dphi, ddphi = _potentials(lam, coefficient, theta)
    z = _power(1.0, theta)
    return dphi + np.conj(dphi) + z**2 * (np.conj(z) * ddphi + lam * B * _power(lam - 1, theta))


def _stress(lam: float, coefficient: np.ndarray, theta: np.ndarray) -> float:
    """The largest |sigma_tt + i sigma_rt| and |sigma_rr + sigma_tt| of a field on the wedge."""
    dphi = _potentials(lam, coefficient, theta)[2]
    traction = _traction(lam, coefficient, theta)
    return float(max(np.abs(traction).max(), np.abs(2 * (dphi + np.conj(dphi))).max()))


def _wedge_matrix(lam: float, angle: float, sides, kappa: float) -> np.ndarray:
    """The 4 x 4 matrix of both sides' conditions (module docstring)."""
    return np.vstack([_side_rows(lam, 0.0, sides[0], kappa),
                      _side_rows(lam, angle, sides[1], kappa)])


def smallest_singular_value(lam: float, angle: float, sides, kappa: float) -> float:
    """sigma_min of the wedge's 4 x 4 matrix with unit columns: zero at an exponent."""
    matrix = _wedge_matrix(lam, angle, sides, kappa)
    norms = np.linalg.norm(matrix, axis=0)
    matrix = matrix / np.where(norms > 0, norms, 1.0)  # a zero column: a stress-free field
    return float(np.linalg.svd(matrix, compute_uv=False)[-1])


def corner_exponents(corner: Corner, kappa: float, upper: float = 3.0) -> list[float]:
    """The real exponents lambda in (0, upper] of ``corner``, ascending, rigid motions left
    out (module docstring)."""
    grid = np.linspace(upper / GRID, upper, GRID)
    values = np.array([smallest_singular_value(g, corner.angle, corner.sides, kappa)
                       for g in grid])
    found = []
    for k in np.flatnonzero((values[1:-1] <= values[:-2]) & (values[1:-1] <= values[2:])) + 1:
        best = minimize_scalar(smallest_singular_value, bracket=(grid[k - 1], grid[k + 1]),
                               args=(corner.angle, corner.sides, kappa),
                               options={"xtol": 1e-13})
        if best.fun < ROOT and not _rigid(best.x, corner, kappa):
            found.append(float(best.x))
    found.sort()
    return [x for k, x in enumerate(found) if k == 0 or x - found[k - 1] > 1e-8]


def _rigid(lam: float, corner: Corner, kappa: float) -> bool:
    null = np.linalg.svd(_wedge_matrix(lam, corner.angle, corner.sides, kappa))[2][-1]
    return _stress(lam, null, np.linspace(0.0, corner.angle, 33)) < 1e-8


def predicted_rate(exponents, order: int, dim: int = 2) -> float:
    """The uniform-refinement rate of the energy error in N (DOFs): -min(lambda, p) / d (h is
    N^(-1/d)), with lambda the smallest exponent of the solution (corners and contact-zone
    ends)."""
    return -min(min(exponents), order) / dim


@dataclass(frozen=True)
class Singularity:
    where: str
    exponent: float


def singularities(scene) -> list[Singularity]:
    """The smallest exponent of each corner of ``scene`` (for its material) and of the ends of
    its contact zone, ascending."""
    kappa = kolosov(scene.material.poisson_ratio, scene.material.plane)
    found = [Singularity("contact-zone ends", CONTACT_END_EXPONENT)]
    for corner in scene.corners:
        exponents = corner_exponents(corner, kappa)
        if exponents:
            found.append(Singularity(f"{corner.sides[0]}/{corner.sides[1]} corner at "
                                     f"({corner.point[0]:g}, {corner.point[1]:g})",
                                     exponents[0]))
    return sorted(found, key=lambda s: s.exponent)

"""Weak symmetry of the equilibrated stress: its skew part orthogonal to every continuous
piecewise linear function (docs/theory.md, section 13.2, "Weak symmetry").

The symmetrising correction of ``estimators.symmetrisation`` adds curl phi (phi in continuous
P_(k+1), 0 where sigma* n is prescribed) and keeps the equilibrium for every phi. Here phi
also satisfies, for every vertex z with hat function psi_z,

    (s(sigma* + curl phi), psi_z) = 0,    s(tau) = (tau_12 - tau_21) / 2,

linear constraints B phi = g with (s(curl phi), psi_z) = -(div(phi_1, phi_2), psi_z) / 2.
Then (skw sigma, skw grad v) = sum_z (psi_z skw sigma, skw grad v - c_z) for any constant
skew matrices c_z (their sum sum_z psi_z c_z is continuous and piecewise linear), which the
local Korn constants of ``estimators.local_korn`` bound without a global constant (13.4).

The constrained minimiser is computed by projected conjugate gradients (Gould, Hribar and
Nocedal's constraint preconditioner, with the inverse node blocks D^-1 of the unconstrained
system): every iterate satisfies B phi = g to the round-off of one sparse factorisation of
S = B D^-1 B' (the default direct back-end), so the objective can stop early
(PROJECTED_RTOL) while the constraints hold.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import aslinearoperator, cg
from skfem import Basis, BilinearForm, ElementTriP1, LinearForm, asm

from estimators.equilibration import Reconstruction
from estimators.patch_data import SCALARS, Interior
from estimators.symmetrisation import (
    MAX_ITERATIONS,
    RTOL,
    curl_values,
    rt_dofs,
    stream_system,
)
from formulations.solvers.backends import factorise

# The projected iterations start from the projection of the unconstrained minimiser, which
# the constraints move far from the constrained one: stopped at RTOL they left eta 10 % above
# equilibrated's on `paper`, mixed, P1, 132 098 DOFs (0.5388 against 0.4880; the symmetric
# part 0.467 against 0.418); at 3e-3 0.4849 (34 solves of S), at 1e-3 0.4800 (89 solves).
PROJECTED_RTOL = 1e-3


@BilinearForm
def _skew_of_curl_first(u, v, w):
    return -0.5 * u.grad[0] * v


@BilinearForm
def _skew_of_curl_second(u, v, w):
    return -0.5 * u.grad[1] * v


@LinearForm
def _against_hats(v, w):
    return w.s * v


def constraint_matrix(rt) -> sp.csr_matrix:
    """B (n_vertices, 2 dim P_(k+1)): (s(curl phi), psi_z) for phi's two rows' values."""
    stream = Basis(rt.mesh, SCALARS[rt.elem.k + 1](), quadrature=rt.quadrature)
    hats = Basis(rt.mesh, ElementTriP1(), quadrature=rt.quadrature)
    return sp.hstack([asm(_skew_of_curl_first, stream, hats),
                      asm(_skew_of_curl_second, stream, hats)]).tocsr()


def hat_moments(rt, density: np.ndarray) -> np.ndarray:
    """(density, psi_z) per vertex for values (n_el, nq) at the points of ``rt``."""
    return asm(_against_hats, Basis(rt.mesh, ElementTriP1(), quadrature=rt.quadrature),
               s=density)


def skew_moments(rt, values: np.ndarray) -> np.ndarray:
    """(s(tau), psi_z) per vertex for a field tau (2, 2, n_el, nq) at the points of ``rt``."""
    return hat_moments(rt, 0.5 * (values[0, 1] - values[1, 0]))


def constrained_stream_function(rt, residual: np.ndarray, values: np.ndarray,
                                prescribed: np.ndarray, lame: tuple[float, float],
                                korn: float) -> np.ndarray:
    """phi (2, dim P_(k+1)) minimising ``estimators.symmetrisation``'s objective subject to
    B phi = -(s(sigma*), psi_z) (module docstring); ``values`` sigma* at the points."""
    system = stream_system(rt, residual, prescribed, lame, korn)
    B = constraint_matrix(rt) @ sp.diags(system.free.astype(float))
    g = -skew_moments(rt, values)
    D = system.blocks
    solve_s = factorise((B @ D @ B.T).tocsc())  # the default direct back-end

    def onto(x: np.ndarray) -> np.ndarray:  # the D-nearest phi with B phi = g
        return x + D @ (B.T @ solve_s(g - B @ x))

    def reduced(r: np.ndarray) -> np.ndarray:  # D^-1 r with its B-part removed: B z = 0
        z = D @ r
        return z - D @ (B.T @ solve_s(B @ z))

    start, _ = cg(system.operator, system.rhs, rtol=RTOL, maxiter=MAX_ITERATIONS,
                  M=aslinearoperator(D))
    x = onto(start * system.free)
    r = system.operator @ x - system.rhs
    z = reduced(r)
    p, rz = -z, r @ z
    first = rz
    for _ in range(MAX_ITERATIONS):
        if rz <= PROJECTED_RTOL**2 * first:
            break
        Ap = system.operator @ p
        alpha = rz / (p @ Ap)
        x, r = x + alpha * p, r + alpha * Ap
        z = reduced(r)
        rz, previous = r @ z, rz
        p = -z + rz / previous * p
    return (onto(x) * system.free).reshape(2, -1)


def weakly_symmetrised(rec: Reconstruction, interior: Interior, prescribed: np.ndarray,
                       lame: tuple[float, float], korn: float) -> tuple[Reconstruction, float]:
    """``rec`` plus curl phi of ``constrained_stream_function``, and the largest |(s(sigma),
    psi_z)| left, relative to the largest (|sigma_12| + |sigma_21|) / 2 moment (round-off)."""
    rt = rec.basis
    phi = constrained_stream_function(rt, rec.values - interior.sigma_h, rec.values,
                                      prescribed, lame, korn)
    correction = curl_values(rt, phi)
    values = rec.values + correction
    scale = hat_moments(rt, 0.5 * (np.abs(values[0, 1]) + np.abs(values[1, 0])))
    defect = np.abs(skew_moments(rt, values)).max() / max(scale.max(), np.finfo(float).tiny)
    return replace(rec, dofs=rec.dofs + rt_dofs(rt, interior.mass, correction),
                   values=values), float(defect)

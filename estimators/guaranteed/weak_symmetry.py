"""Weak symmetry of the equilibrated stress: its skew part orthogonal to every continuous
piecewise linear function (docs/theory.md, section 13.2, "Weak symmetry").

The symmetrising correction of ``estimators.guaranteed.symmetrisation`` adds curl phi (phi in
continuous P_(k+1), 0 where sigma* n is prescribed) and keeps the equilibrium for every phi. Here
phi also satisfies, for every vertex z with hat function psi_z,

    (s(sigma* + curl phi), psi_z) = 0,    s(tau) = (tau_12 - tau_21) / 2,

linear constraints B phi = g with (s(curl phi), psi_z) = -(div(phi_1, phi_2), psi_z) / 2.
Then (skw sigma, skw grad v) = sum_z (psi_z skw sigma, skw grad v - c_z) for any constant
skew matrices c_z (their sum sum_z psi_z c_z is continuous and piecewise linear), which the
local Korn constants of ``estimators.guaranteed.local_korn`` bound without a global constant (13.4).

The constrained minimiser solves the saddle-point system [A B'; B 0] (A the minimisation's
matrix, y the multipliers): with A factorised once by the default direct back-end, conjugate
gradients on B A^-1 B' y = B A^-1 b - g, which is spectrally like a P1 mass matrix and needs
about ten iterations whatever h (preconditioned by its diagonal with diag(A) for A). Above
DIRECT_UNKNOWNS, which bounds that factorisation's memory, projected conjugate gradients
(Gould, Hribar and Nocedal's constraint preconditioner, with the inverse node blocks D^-1 of
the unconstrained system) keep every iterate on B phi = g by one sparse factorisation of
S = B D^-1 B' and stop at PROJECTED_RTOL. Either way the last step projects onto B phi = g
with S, to round-off.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import LinearOperator, aslinearoperator, cg
from skfem import Basis, BilinearForm, ElementTriP1, LinearForm, asm

from estimators.guaranteed.equilibration import Reconstruction
from estimators.guaranteed.patch_data import SCALARS, Interior
from estimators.guaranteed.rt_reference import summed_matrix
from estimators.guaranteed.symmetrisation import (
    MAX_ITERATIONS,
    RTOL,
    StreamElements,
    curl_values,
    node_blocks,
    rt_dofs,
    stream_elements,
    stream_system,
)
from formulations.solvers.backends import factorise

# Above this many unknowns (2 dim P_(k+1)) the projected iterations replace the factorisation
# of A: at 2.1e6 (`paper`, mixed, P1, 526 338 DOFs) the direct route took 54 s (factorisation
# 19 s) and 7.0 GiB at peak for the whole estimate, the projected iterations 83 s.
DIRECT_UNKNOWNS = 2_500_000
# CG on the multipliers: at 1e-3 (11 iterations) eta agrees with 1e-6 (20) to 1e-7 relative
# (`paper`, mixed, P1, 33 282 DOFs), the last projection mending the constraints.
SCHUR_RTOL = 1e-3
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


def stream_matrix(elements: StreamElements) -> sp.csr_matrix:
    """A assembled, with the identity on the pinned values' rows and columns."""
    index, free = elements.index, elements.free
    kept = free[index].astype(float)
    local = elements.matrices * kept[:, :, None] * kept[:, None, :]
    return (summed_matrix(local, index, free.size) + sp.diags((~free).astype(float))).tocsr()


def multiplier_iterations(elements: StreamElements, B: sp.csr_matrix,
                          g: np.ndarray) -> np.ndarray:
    """The minimiser subject to B phi = g by CG on the multipliers (module docstring)."""
    A = stream_matrix(elements)
    solve_a = factorise(A.tocsc())  # the default direct back-end
    unconstrained = solve_a(elements.rhs)
    scale = abs(B).power(2) @ (1.0 / A.diagonal())
    schur = LinearOperator((B.shape[0],) * 2, matvec=lambda y: B @ solve_a(B.T @ y),
                           dtype=float)
    y, _ = cg(schur, B @ unconstrained - g, rtol=SCHUR_RTOL, maxiter=MAX_ITERATIONS,
              M=sp.diags(1.0 / np.where(scale > 0, scale, 1.0)))
    return unconstrained - solve_a(B.T @ y)


def projected_iterations(elements: StreamElements, onto, reduced) -> np.ndarray:
    """The minimiser subject to B phi = g by projected CG (module docstring): ``onto`` the
    D-nearest point on the constraints, ``reduced`` D^-1 r with its B-part removed."""
    system = stream_system(elements)
    start, _ = cg(system.operator, system.rhs, rtol=RTOL, maxiter=MAX_ITERATIONS,
                  M=aslinearoperator(system.blocks))
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
    return x


def constrained_stream_function(rt, residual: np.ndarray, values: np.ndarray,
                                prescribed: np.ndarray, lame: tuple[float, float],
                                korn: float) -> np.ndarray:
    """phi (2, dim P_(k+1)) minimising ``estimators.guaranteed.symmetrisation``'s objective subject
    to B phi = -(s(sigma*), psi_z) (module docstring); ``values`` sigma* at the points."""
    elements = stream_elements(rt, residual, prescribed, lame, korn)
    B = (constraint_matrix(rt) @ sp.diags(elements.free.astype(float))).tocsr()
    g = -skew_moments(rt, values)
    D = node_blocks(elements)
    solve_s = factorise((B @ D @ B.T).tocsc())  # the default direct back-end

    def onto(x: np.ndarray) -> np.ndarray:  # the D-nearest phi with B phi = g
        return x + D @ (B.T @ solve_s(g - B @ x))

    def reduced(r: np.ndarray) -> np.ndarray:  # D^-1 r with its B-part removed: B z = 0
        z = D @ r
        return z - D @ (B.T @ solve_s(B @ z))

    if elements.free.size <= DIRECT_UNKNOWNS:
        x = multiplier_iterations(elements, B, g)
    else:
        x = projected_iterations(elements, onto, reduced)
    return (onto(x) * elements.free).reshape(2, -1)


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
    return replace(rec, dofs=rec.dofs + rt_dofs(rt, interior, correction),
                   values=values), float(defect)

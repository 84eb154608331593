"""Contact problems that are a piecewise linear equation rather than a QP (docs/theory.md,
section 12): Nitsche's method, and any formulation of the same shape.

``SemismoothSystem`` holds, over the free DOFs,

    K u + S' phi_S(z) + N' phi_N(z) = F,   z = (s, v) = (S u, N u),

where S gives sigma_nn(u_h) and N gives u_h . n at the quadrature points x_q of Gamma_C, and
with P_q = s_q + gamma_q (g_q - v_q) (the Nitsche pressure) and m_q = min(P_q, 0),

    phi_S = (theta / gamma) W (m - s),   phi_N = -W m,   W = diag(w_q) (weights x facet length).

This is eq. (12.2) of docs/theory.md written on the contact values z only: the nonlinearity
lives in the few entries of z, which is what lets a solver condense onto them. The discrete
pressure is lambda_q = -m_q >= 0.

S may have no rows: then z = N u, P_q = gamma_q (g_q - v_q) and the equation is
K u + N' W gamma (N u - g)_+ = F, the penalty method with eps = 1 / gamma (docs/theory.md,
section 3).

A solution checks itself: ``residuals`` computes the relative nonlinear residual from u alone
(the pressure is a function of u, so a dual violation or a complementarity gap cannot occur).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
from scipy import sparse

from formulations.base import Residuals


@dataclass(frozen=True, eq=False)
class SemismoothSystem:
    """The equation of the module docstring over the free DOFs."""

    K: sparse.csr_matrix
    F: np.ndarray
    S: sparse.csr_matrix  # sigma_nn at the quadrature points (nq x n; or 0 x n: no such term)
    N: sparse.csr_matrix  # u . n at the quadrature points (nq x n)
    gap: np.ndarray  # g at the quadrature points
    weight: np.ndarray  # quadrature weight x facet length
    gamma: np.ndarray  # the Nitsche parameter at the quadrature points (a stress per length)
    theta: float
    objective_scale: float  # Young's modulus: the scale of K
    # K's rigid-body modes (``Elasticity.rigid_modes``): the near-null space of the ``amg``
    # back-end (None: none known; the back-end is then slower, not wrong)
    near_null: np.ndarray | None = None

    @property
    def n(self) -> int:
        return int(self.F.size)

    @property
    def nq(self) -> int:
        return int(self.gap.size)

    @property
    def ns(self) -> int:
        """Rows of S: nq, or 0 for a system without the sigma_nn term (a penalty)."""
        return int(self.S.shape[0])

    @cached_property
    def T(self) -> sparse.csr_matrix:
        """u -> z = (S u, N u) (built once)."""
        return sparse.vstack([self.S, self.N], format="csr")

    def pressure_argument(self, z: np.ndarray) -> np.ndarray:
        """P = sigma_nn + gamma (g - u_n) at the quadrature points."""
        s, v = z[: self.ns], z[self.ns:]
        return (s if self.ns else 0.0) + self.gamma * (self.gap - v)

    def phi(self, z: np.ndarray) -> np.ndarray:
        """(phi_S, phi_N) of the module docstring."""
        return self.phi_of(z[: self.ns], np.minimum(self.pressure_argument(z), 0.0))

    def phi_of(self, s: np.ndarray, m: np.ndarray) -> np.ndarray:
        """(phi_S, phi_N) from sigma_nn = s and m = [P]_- at the quadrature points (phi_N
        alone without S)."""
        w = self.weight
        if not self.ns:
            return -w * m
        return np.concatenate([self.theta / self.gamma * w * (m - s), -w * m])

    def phi_affine(self, active: np.ndarray) -> tuple[sparse.csr_matrix, np.ndarray]:
        """phi(z) = D z + c where ``active`` (P < 0) is fixed: (D, c)."""
        chi = active.astype(float)
        w, gamma, theta = self.weight, self.gamma, self.theta
        if not self.ns:
            return sparse.diags(gamma * w * chi, format="csr"), -gamma * w * chi * self.gap
        D = sparse.bmat([[sparse.diags(theta / gamma * w * (chi - 1.0)),
                          sparse.diags(-theta * w * chi)],
                         [sparse.diags(-w * chi), sparse.diags(gamma * w * chi)]], format="csr")
        c = np.concatenate([theta * w * chi * self.gap, -gamma * w * chi * self.gap])
        return D, c

    def pressure(self, u: np.ndarray) -> np.ndarray:
        """lambda_q = -min(P_q, 0) >= 0 at the quadrature points."""
        return -np.minimum(self.pressure_argument(self.T @ u), 0.0)

    def residual(self, u: np.ndarray) -> np.ndarray:
        """K u + T' phi(T u) - F."""
        return self.scaled_residual(u)[0]

    def scaled_residual(self, u: np.ndarray) -> tuple[np.ndarray, float]:
        """K u + T' phi(T u) - F and its scale, the largest of ||K u||, ||F|| and ||T' phi||
        (1 when they all vanish)."""
        contact = self.T.T @ self.phi(self.T @ u)
        Ku = self.K @ u
        scale = max(np.linalg.norm(Ku), np.linalg.norm(self.F), np.linalg.norm(contact))
        return Ku + contact - self.F, scale if scale > 0 and np.isfinite(scale) else 1.0

    def residuals(self, u: np.ndarray) -> Residuals:
        """The relative nonlinear residual as ``stationarity``; the other residuals vanish by
        construction."""
        r, scale = self.scaled_residual(u)
        return Residuals(violation=0.0, dual_violation=0.0, complementarity=0.0,
                         stationarity=float(np.linalg.norm(r) / scale))

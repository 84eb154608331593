"""The stress tau that carries a formulation's consistency term into the patch data
(docs/theory.md, 13.2, "Balance"): where the discrete equation reads

    a(u_h, v) - (q, sigma(v) n)_{Gamma_C} = L(v) - (lambda_h, v . n)_{Gamma_C}
                                            + (sigma_t,h, v_t)_{Gamma_C}

(Nitsche: q = theta/gamma times the traction residual, ``formulations.base.ConsistencyTerm``),
(q, sigma(v) n)_F = (C sym(q x n), grad v)_F, and for the hat functions v = psi_a e_r, whose
gradients are constant on the element T at F, it equals (tau, grad v)_T with the constant

    tau_T = |T|^-1 sum_(F in T) C sym(int_F q x n).

sigma_h - tau then balances every patch in the divergence data, and the load rho that would
carry this term (of size |q| / h) is not needed; the patch problems still approximate
psi_a sigma_h, and the bound still measures sigma* - sigma_h.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from estimators.guaranteed.patch_data import Interior, hat_moments, vertex_totals
from formulations import DiscreteSolution
from formulations.cells.p1_stiffness import barycentric_gradients


def consistency_stress(solution: DiscreteSolution) -> np.ndarray | None:
    """tau_T (d, d, n_elements) of the module docstring, None without a consistency term."""
    term = solution.consistency
    if term is None:
        return None
    trace, mesh = solution.trace, solution.elasticity.mesh
    d = mesh.dim()
    q = (term.vector * term.weights.reshape(trace.size, -1)).sum(axis=-1)    # (d, n_f)
    outer = 0.5 * (q[:, None] * trace.normal[None] + trace.normal[:, None] * q[None])
    lam, mu = solution.elasticity.lame
    stress = 2 * mu * outer + lam * np.einsum("iif->f", outer) * np.eye(d)[:, :, None]
    n_el = mesh.t.shape[1]
    summed = np.array([[np.bincount(trace.element, stress[i, j], minlength=n_el)
                        for j in range(d)] for i in range(d)])
    return summed / barycentric_gradients(mesh)[1]


def with_consistency(interior: Interior, tau: np.ndarray | None) -> Interior:
    """The patch data of sigma_h - tau: int_T (tau grad psi_a)_r q_l taken from the divergence
    data of every (element, vertex a, row r, P_k function q_l) and from the vertex totals."""
    if tau is None:
        return interior
    mesh = interior.rt.mesh
    gradients, volume = barycentric_gradients(mesh)                         # (d + 1, d, n_el)
    mean = hat_moments(interior.k, mesh.dim()).sum(axis=0)                  # int_T q_l / |T|
    moments = np.einsum("rce,ace,e,l->earl", tau, gradients, volume, mean)
    data = interior.data - moments
    return replace(interior, data=data, total=vertex_totals(mesh, data))

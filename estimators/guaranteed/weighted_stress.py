"""The weighted norm of RT_k stresses in the bound's terms (docs/theory.md, section 13.2):
tau : W : tau = sym tau : C^-1 sym tau + c^2 |skw tau|^2 (plane strain), its element matrices
on the two rows' RT_k functions and its linear term against a given field (used where f jumps,
``estimators.guaranteed.jump_equilibration``)."""

from __future__ import annotations

import numpy as np

from estimators.guaranteed.rt_reference import orientations, reference_rt, rt_moments


def stress_weight(lame: tuple[float, float], korn: float) -> np.ndarray:
    """W (4, 4) with tau : W : tau = sym tau : C^-1 sym tau + C_K^2 |skw tau|^2, entries in
    the order tau_00, tau_01, tau_10, tau_11 (row, component), in plane strain."""
    lam, mu = lame
    kappa = lam / (2 * (lam + mu))
    W = np.zeros((4, 4))
    W[0, 0] = W[3, 3] = (1 - kappa) / (2 * mu)
    W[0, 3] = W[3, 0] = -kappa / (2 * mu)
    W[1, 1] = W[2, 2] = 1 / (4 * mu) + korn**2 / 2
    W[1, 2] = W[2, 1] = 1 / (4 * mu) - korn**2 / 2
    return W


def energy_blocks(sub, k: int, X, W, weight: np.ndarray) -> np.ndarray:
    """(tau, tau)_W per element on the two rows' RT_k functions, (n_sub, 2 n_rt, 2 n_rt): the
    Piola components phi_j,c = o_j (J phi^_j)_c / |det J| against ``weight``."""
    mapping = sub.mapping()
    J, det = mapping.A, np.abs(mapping.detA)
    phi, _ = reference_rt(k, X)
    n_rt = phi.shape[0]
    o = orientations(sub, n_rt, k)
    reference = np.einsum("jap,lbp,p->abjl", phi, phi, W)
    components = np.einsum("cae,dbe,abjl->cdejl", J, J, reference, optimize=True)
    components *= (o[:, :, None] * o[:, None, :] / det[:, None, None])[None, None]
    local = np.einsum("rcsd,cdejl->erjsl", weight.reshape(2, 2, 2, 2), components,
                      optimize=True)
    return local.reshape(-1, 2 * n_rt, 2 * n_rt)


def weighted_moments(rt, weight: np.ndarray, field: np.ndarray) -> np.ndarray:
    """(phi_j, field)_W for the two rows' RT_k functions, (2 N,) rows one after the other:
    the linear term of ||field - tau||_W^2 (``stress_weight``'s W, field (2, 2, n, nq))."""
    X, W = rt.quadrature
    weighted = (weight @ field.reshape(4, -1)).reshape(field.shape)
    moments = rt_moments(rt.mesh, rt.elem.k, X, W, weighted, np.ones((1, W.size)))[:, 0]
    out = np.zeros((2, rt.N))
    for r in (0, 1):
        np.add.at(out[r], rt.element_dofs.T, moments[:, r])
    return out.ravel()

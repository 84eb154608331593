"""The symmetrising correction of the equilibrated stress on tetrahedra (docs/theory.md,
section 14.5; the triangles' ``estimators.symmetrisation`` in 3D).

Row r of sigma* gets the curl of a vector potential psi_r in continuous P2^3. Every curl
keeps what the bound needs: curl P2^3 lies in P1^3, inside RT_k for k >= 1; div curl = 0; a
continuous psi has a curl with continuous normal component; and n . curl psi is the surface
divergence of psi x n, zero on a facet where psi vanishes. With psi = 0 on the facets where
sigma* n is prescribed (Gamma_N and Gamma_C), sigma* + curl psi equilibrates the same data, so
every psi keeps the bound; the one taken minimises

    ||C^{-1/2}(sym(sigma* + curl psi) - sigma_h)||^2 + w ||skw(sigma* + curl psi)||^2,

w = WEIGHT C_K^2, by conjugate gradients on the element matrices (the system is only
semidefinite: gradients have no curl, and CG on a consistent system does not mind). With
(curl psi)_c = sum_(a,b) eps_cab d_a psi_b and d_a = sum_e (J^-1)_ea d^_e, every element matrix
is a reference tensor of the P2 gradients contracted with H_cbe = sum_a eps_cab (J^-1)_ea.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from scipy.sparse.linalg import LinearOperator, cg
from skfem import ElementTetP2
from skfem.assembly import Dofs

from estimators.equilibration import Reconstruction
from estimators.patch_classes import Classes, equal_rows
from estimators.patch_data import Interior
from estimators.rt_reference import ReferenceRT
from estimators.symmetrisation import MAX_ITERATIONS, RTOL, WEIGHT, rt_dofs

_LEVI_CIVITA = np.zeros((3, 3, 3))
for _c, _a, _b in ((0, 1, 2), (1, 2, 0), (2, 0, 1)):
    _LEVI_CIVITA[_c, _a, _b], _LEVI_CIVITA[_c, _b, _a] = 1.0, -1.0


def density(lam: float, mu: float, weight: float) -> np.ndarray:
    """Q (3, 3, 3, 3): q(T, S) = C^-1 sym T : sym S + weight skw T : skw S, with
    ``estimators.averaging.compliance_energy``'s 3D compliance."""
    unit = np.eye(9).reshape(9, 3, 3)
    sym, skw = 0.5 * (unit + unit.transpose(0, 2, 1)), 0.5 * (unit - unit.transpose(0, 2, 1))
    trace = np.trace(sym, axis1=1, axis2=2)
    compliance = (np.einsum("arc,brc->ab", sym, sym)
                  - lam / (3 * lam + 2 * mu) * np.outer(trace, trace)) / (2 * mu)
    return (compliance + weight * np.einsum("arc,brc->ab", skw, skw)).reshape(3, 3, 3, 3)


def curl_map(mesh) -> np.ndarray:
    """H (n_el, 3, 3, 3): (curl psi)_c = sum_(b,e) H[c, b, e] d^_e psi_b on every element."""
    return np.einsum("cab,eak->kcbe", _LEVI_CIVITA, mesh.mapping().invA)


def potential_gradients(X: np.ndarray) -> np.ndarray:
    """The reference gradients (10, 3, nq) of the P2 basis at the points X."""
    element = ElementTetP2()
    return np.array([element.lbasis(X, j)[1] for j in range(10)])


def element_system(rt: ReferenceRT, Q: np.ndarray, residual: np.ndarray,
                   elements: np.ndarray):
    """The element matrices (n, 90, 90) of q(curl psi, curl chi) for the ``elements`` and the
    vectors (n_el, 90) of -q(residual, curl chi) for residual (3, 3, n_el, nq) at the points
    of ``rt``; unknowns ordered (row r, component b, local P2 function j)."""
    mesh, (X, W) = rt.mesh, rt.quadrature
    grad = potential_gradients(X)                                        # (10, 3, nq)
    H, det = curl_map(mesh), np.abs(mesh.mapping().detA)
    reference = np.einsum("iep,jfp,p->efij", grad, grad, W)              # (3, 3, 10, 10)
    Hc = H[elements]
    coupling = np.einsum("rcsd,kcbe,kdgf,k->krbesgf", Q, Hc, Hc, det[elements])
    matrices = np.einsum("krbesgf,efij->krbisgj", coupling, reference, optimize=True)
    n_el, nq = residual.shape[2:]
    tested = (Q.reshape(9, 9).T @ residual.reshape(9, -1)).reshape(3, 3, n_el, nq)  # s d k p
    weighted = tested.transpose(2, 0, 1, 3) * (W[None, :] * det[:, None])[:, None, None]
    pulled = weighted @ grad.transpose(2, 1, 0).reshape(nq, 30)          # (k, s, d, f j)
    pulled = pulled.reshape(n_el, 3, 9, 10).transpose(0, 1, 3, 2)        # (k, s, j, d f)
    vectors = -(pulled @ H.transpose(0, 1, 3, 2).reshape(n_el, 9, 3)[:, None])  # (k,s,j,g)
    n = len(elements)
    return matrices.reshape(n, 90, 90), vectors.transpose(0, 1, 3, 2).reshape(-1, 90)


def potential(rt: ReferenceRT, residual: np.ndarray, prescribed: np.ndarray,
              lame: tuple[float, float], korn: float) -> np.ndarray:
    """psi (3 rows, 3 components, dim P2) of the module docstring, by conjugate gradients
    preconditioned by the inverse node blocks of ``node_blocks``, to RTOL."""
    dofs = Dofs(rt.mesh, ElementTetP2())
    n = dofs.N
    # an element matrix depends on the element only through |det J|^(1/2) H: translation
    # leaves it alone
    scaled = curl_map(rt.mesh) * np.sqrt(np.abs(rt.mesh.mapping().detA))[:, None, None, None]
    classes = Classes.of_owners(equal_rows([scaled]))
    matrices, vectors = element_system(rt, density(*lame, WEIGHT * korn**2), residual,
                                       classes.first)
    index = np.vstack([dofs.element_dofs + field * n for field in range(9)]).T   # (n_el, 90)
    free = np.ones(9 * n, dtype=bool)
    if prescribed.size:
        pinned = dofs.get_facet_dofs(prescribed).all()
        free[(pinned[None, :] + n * np.arange(9)[:, None]).ravel()] = False
    single = matrices.astype(np.float32)
    ordered = index[classes.order]

    def apply(x: np.ndarray) -> np.ndarray:
        local = (x * free).astype(np.float32)[ordered]
        return np.bincount(ordered.ravel(), classes.products(single, local).ravel(),
                           minlength=free.size) * free

    blocks = node_blocks(matrices, classes, dofs.element_dofs, free.reshape(9, n))
    rhs = np.bincount(index.ravel(), vectors.ravel(), minlength=free.size) * free
    operator = LinearOperator((free.size,) * 2, matvec=apply, dtype=float)
    preconditioner = LinearOperator(
        (free.size,) * 2, dtype=float,
        matvec=lambda r: np.einsum("nab,bn->an", blocks, r.reshape(9, n)).ravel())
    psi, _ = cg(operator, rhs, rtol=RTOL, maxiter=MAX_ITERATIONS, M=preconditioner)
    return (psi * free).reshape(3, 3, n)


def node_blocks(matrices: np.ndarray, classes: Classes, element_dofs: np.ndarray,
                free: np.ndarray) -> np.ndarray:
    """The inverses (n, 9, 9) of the blocks that couple the nine fields at each P2 node (the
    skew weight and the curl couple them), restricted to the free fields: a block-Jacobi
    preconditioner."""
    n_nodes = free.shape[1]
    local = matrices.reshape(-1, 9, 10, 9, 10)
    diagonal = np.einsum("kajbj->kjab", local)[classes.of]              # (n_el, 10, 9, 9)
    blocks = np.zeros((n_nodes, 81))
    for j in range(10):
        np.add.at(blocks, element_dofs[j], diagonal[:, j].reshape(-1, 81))
    blocks = blocks.reshape(n_nodes, 9, 9)
    mask = free.T[:, :, None] & free.T[:, None, :]
    blocks = np.where(mask, blocks, 0.0) + np.eye(9) * (~free.T)[:, :, None]
    inverse = np.linalg.inv(blocks)
    return inverse * mask


def curl_values(rt: ReferenceRT, psi: np.ndarray) -> np.ndarray:
    """curl psi_r as row r (3, 3, n_el, nq) at the points of ``rt``."""
    local = psi[:, :, Dofs(rt.mesh, ElementTetP2()).element_dofs]       # (3, 3, 10, n_el)
    grad = potential_gradients(rt.quadrature[0])                        # (10, 3, nq)
    n_el, nq = local.shape[3], grad.shape[2]
    derivatives = local.reshape(9, 10, n_el).transpose(2, 0, 1) @ grad.reshape(10, -1)
    derivatives = derivatives.reshape(n_el, 3, 3, 3, nq).transpose(0, 2, 3, 1, 4)  # k b e r p
    curl = curl_map(rt.mesh).reshape(n_el, 3, 9) @ derivatives.reshape(n_el, 9, 3 * nq)
    return curl.reshape(n_el, 3, 3, nq).transpose(2, 1, 0, 3)           # (r, c, k, p)


def symmetrised(rec: Reconstruction, interior: Interior, prescribed: np.ndarray,
                lame: tuple[float, float], korn: float) -> Reconstruction:
    """``rec`` plus the curls of the minimising potentials (module docstring), with its RT_k
    DOFs; ``prescribed`` the facets where sigma* n is prescribed."""
    rt = rec.basis
    psi = potential(rt, rec.values - interior.sigma_h, prescribed, lame, korn)
    correction = curl_values(rt, psi)
    return replace(rec, dofs=rec.dofs + rt_dofs(rt, interior, correction),
                   values=rec.values + correction)

"""The symmetrising correction of the equilibrated stress on tetrahedra (docs/theory.md,
section 14.5; the triangles' ``estimators.guaranteed.symmetrisation`` in 3D).

Row r of sigma* gets the curl of a vector potential psi_r in continuous P2^3. Every curl
keeps what the bound needs: curl P2^3 lies in P1^3, inside RT_k for k >= 1; div curl = 0; a
continuous psi has a curl with continuous normal component; and n . curl psi is the surface
divergence of psi x n, zero on a facet where psi vanishes. With psi = 0 on the facets where
sigma* n is prescribed (Gamma_N and Gamma_C), sigma* + curl psi equilibrates the same data, so
every psi keeps the bound; the one taken minimises

    ||C^{-1/2}(sym(sigma* + curl psi) - sigma_h)||^2 + w ||skw(sigma* + curl psi)||^2,

w = WEIGHT C_K^2, by conjugate gradients (the system is only semidefinite: gradients have
no curl, and CG on a consistent system does not mind). The products are matrix-free: with
(curl psi)_c = sum_(a,b) eps_cab d_a psi_b and d_a = sum_e (J^-1)_ea d^_e, curl psi at the four
points of the degree-2 rule is the reference P2 gradients contracted with H_cbe = sum_a
eps_cab (J^-1)_ea, and q is applied there (exact: curl psi is linear). Bisected tetrahedra
repeat few shapes, so element matrices shared by classes of elements (as on triangles) do not
pay in 3D.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import LinearOperator, cg
from skfem import ElementTetP2
from skfem.assembly import Dofs
from skfem.quadrature import get_quadrature
from skfem.refdom import RefTet

from estimators.guaranteed.equilibration import Reconstruction
from estimators.guaranteed.patch_data import Interior
from estimators.guaranteed.rt_reference import ReferenceRT
from estimators.guaranteed.symmetrisation import MAX_ITERATIONS, RTOL, WEIGHT, rt_dofs

_LEVI_CIVITA = np.zeros((3, 3, 3))
for _c, _a, _b in ((0, 1, 2), (1, 2, 0), (2, 0, 1)):
    _LEVI_CIVITA[_c, _a, _b], _LEVI_CIVITA[_c, _b, _a] = 1.0, -1.0


def density_parts(lam: float, mu: float, weight: float) -> tuple[float, float, float]:
    """(a, b, c) with q(T, S) = a T : S + b T : S^T + c tr T tr S, for q(T, S) = C^-1 sym T :
    sym S + weight skw T : skw S and ``estimators.averaging.compliance_energy``'s 3D
    compliance C^-1 S = (S - lam / (3 lam + 2 mu) tr S I) / (2 mu)."""
    return (1 / (4 * mu) + weight / 2, 1 / (4 * mu) - weight / 2,
            -lam / ((3 * lam + 2 * mu) * 2 * mu))


def density(lam: float, mu: float, weight: float) -> np.ndarray:
    """Q (3, 3, 3, 3) of q(T, S) = sum Q[r, c, s, d] T[r, c] S[s, d] (``density_parts``)."""
    a, b, c = density_parts(lam, mu, weight)
    eye = np.eye(3)
    return (a * np.einsum("rs,cd->rcsd", eye, eye) + b * np.einsum("rd,cs->rcsd", eye, eye)
            + c * np.einsum("rc,sd->rcsd", eye, eye))


def curl_map(mesh) -> np.ndarray:
    """H (n_el, 3, 3, 3): (curl psi)_c = sum_(b,e) H[c, b, e] d^_e psi_b on every element."""
    return np.einsum("cab,eak->kcbe", _LEVI_CIVITA, mesh.mapping().invA)


def potential_gradients(X: np.ndarray) -> np.ndarray:
    """The reference gradients (10, 3, nq) of the P2 basis at the points X."""
    element = ElementTetP2()
    return np.array([element.lbasis(X, j)[1] for j in range(10)])


@dataclass(frozen=True, eq=False)
class CurlEnergy:
    """q(curl psi, curl chi) integrated, element by element through the points of the
    degree-2 rule (curl P2^3 lies in P1^3: exact), for unknowns ordered (row r, component b,
    local P2 function j): ``gradients`` (10, 12) the reference P2 gradients (e p), ``curl``
    (n_el, 3, 9) H (c, b e), ``weights`` (n_el, 4) |det J| w_p and ``Q`` (9, 9)."""

    gradients: np.ndarray
    curl: np.ndarray
    weights: np.ndarray
    Q: np.ndarray

    @classmethod
    def of(cls, mesh, Q: np.ndarray, dtype=np.float64) -> CurlEnergy:
        X, W = get_quadrature(RefTet, 2)
        grad = potential_gradients(X).reshape(10, 12)
        weights = np.abs(mesh.mapping().detA)[:, None] * W[None, :]
        return cls(grad.astype(dtype), curl_map(mesh).reshape(-1, 3, 9).astype(dtype),
                   weights.astype(dtype), Q.reshape(9, 9).astype(dtype))

    def curls(self, local: np.ndarray) -> np.ndarray:
        """(curl psi_r)_c (n_el, 4 p, 9 (r c)) of the local values (n_el, 9 (r b), 10)."""
        n_el = local.shape[0]
        derivatives = (local.reshape(-1, 10) @ self.gradients).reshape(n_el, 3, 9, 4)
        curl = self.curl @ derivatives.transpose(0, 2, 1, 3).reshape(n_el, 9, 12)
        return curl.reshape(n_el, 3, 3, 4).transpose(0, 3, 2, 1).reshape(n_el, 4, 9)

    def tested(self, values: np.ndarray) -> np.ndarray:
        """The local vectors (n_el, 9 (s g), 10) of sum_p values_p : curl chi_p, for values
        (n_el, 4 p, 9 (s d)): the transpose of ``curls``."""
        n_el = values.shape[0]
        by_d = values.reshape(n_el, 4, 3, 3).transpose(0, 3, 2, 1).reshape(n_el, 3, 12)
        pulled = self.curl.transpose(0, 2, 1) @ by_d                        # k (g f) (s p)
        pulled = pulled.reshape(n_el, 3, 3, 3, 4).transpose(0, 3, 1, 2, 4)  # k s g f p
        return (pulled.reshape(-1, 12) @ self.gradients.T).reshape(n_el, 9, 10)

    def apply(self, local: np.ndarray) -> np.ndarray:
        """The element products (n_el, 9, 10) of the energy's matrices with ``local``."""
        curls = self.curls(local)
        tested = (curls.reshape(-1, 9) @ self.Q).reshape(curls.shape)
        return self.tested(tested * self.weights[:, :, None])


def residual_vectors(rt: ReferenceRT, Q: np.ndarray, residual: np.ndarray) -> np.ndarray:
    """-q(residual, curl chi) (n_el, 9 (s g), 10) for residual (3, 3, n_el, nq) at the
    points of ``rt`` (whose rule integrates it)."""
    mesh, (X, W) = rt.mesh, rt.quadrature
    grad = potential_gradients(X)                                        # (10, 3, nq)
    n_el, nq = residual.shape[2:]
    det = np.abs(mesh.mapping().detA)
    tested = (Q.reshape(9, 9).T @ residual.reshape(9, -1)).reshape(3, 3, n_el, nq)  # s d k p
    weighted = tested.transpose(2, 0, 1, 3) * (W[None, :] * det[:, None])[:, None, None]
    pulled = weighted @ grad.transpose(2, 1, 0).reshape(nq, 30)          # (k, s, d, f j)
    pulled = pulled.reshape(n_el, 3, 9, 10).transpose(0, 1, 3, 2)        # (k, s, j, d f)
    vectors = -(pulled @ curl_map(mesh).transpose(0, 1, 3, 2).reshape(n_el, 9, 3)[:, None])
    return vectors.transpose(0, 1, 3, 2).reshape(n_el, 9, 10)            # (k, s g, j)


def potential(rt: ReferenceRT, residual: np.ndarray, prescribed: np.ndarray,
              lame: tuple[float, float], korn: float) -> np.ndarray:
    """psi (3 rows, 3 components, dim P2) of the module docstring, by conjugate gradients
    preconditioned by the inverse node blocks of ``node_blocks``, to RTOL. The products are
    matrix-free and in float32 (any psi keeps the bound); a sparse scatter matrix sums them."""
    dofs = Dofs(rt.mesh, ElementTetP2())
    n = dofs.N
    parts = density_parts(*lame, WEIGHT * korn**2)
    Q = density(*lame, WEIGHT * korn**2)
    index = (dofs.element_dofs.T[:, None, :] + n * np.arange(9)[None, :, None])  # (n_el,9,10)
    free = np.ones(9 * n, dtype=bool)
    if prescribed.size:
        pinned = dofs.get_facet_dofs(prescribed).all()
        free[(pinned[None, :] + n * np.arange(9)[:, None]).ravel()] = False
    energy = CurlEnergy.of(rt.mesh, Q, np.float32)
    scatter = sp.csr_matrix((np.ones(index.size, dtype=np.float32),
                             (index.ravel(), np.arange(index.size))),
                            shape=(free.size, index.size))

    def apply(x: np.ndarray) -> np.ndarray:
        local = (x * free).astype(np.float32)[index]
        return (scatter @ energy.apply(local).ravel()).astype(float) * free

    blocks = node_blocks(energy, dofs.element_dofs, free.reshape(9, n), parts)
    rhs = np.bincount(index.ravel(), residual_vectors(rt, Q, residual).ravel(),
                      minlength=free.size) * free
    operator = LinearOperator((free.size,) * 2, matvec=apply, dtype=float)
    preconditioner = LinearOperator(
        (free.size,) * 2, dtype=float,
        matvec=lambda r: np.einsum("nab,bn->an", blocks, r.reshape(9, n)).ravel())
    psi, _ = cg(operator, rhs, rtol=RTOL, maxiter=MAX_ITERATIONS, M=preconditioner)
    return (psi * free).reshape(3, 3, n)


def node_blocks(energy: CurlEnergy, element_dofs: np.ndarray, free: np.ndarray,
                parts: tuple[float, float, float]) -> np.ndarray:
    """The inverses (n, 9, 9) of the blocks that couple the nine fields at each P2 node (the
    skew weight and the curl couple them), restricted to the free fields: a block-Jacobi
    preconditioner. With ``density_parts`` (a, b, c) and M_p = the map from the fields'
    unit values at node j to curl psi at point p (T = Psi M_p^T), the element's block is
    sum_p w_p [a I (x) M_p^T M_p + b (M_p[s, b] M_p[r, g]) + c vec M_p vec M_p^T]."""
    a, b, c = parts
    n_nodes, n_el = free.shape[1], element_dofs.shape[1]
    blocks = np.zeros((n_nodes, 81))
    H = energy.curl.astype(float)                                          # k c (b e)
    grad = energy.gradients.reshape(10, 3, 4).astype(float)                # j e p
    w = energy.weights.astype(float)[:, :, None]
    for j in range(10):
        M = (H.reshape(-1, 3) @ grad[j]).reshape(n_el, 9, 4).transpose(0, 2, 1)  # k p (c b)
        outer = M.transpose(0, 2, 1) @ (w * M)                            # k (s b) (r g)
        gram = np.einsum("kcbcg->kbg", outer.reshape(n_el, 3, 3, 3, 3))
        block = (b * outer.reshape(n_el, 3, 3, 3, 3).transpose(0, 3, 2, 1, 4) + c * outer
                 .reshape(n_el, 3, 3, 3, 3) + a * np.einsum("rs,kbg->krbsg", np.eye(3), gram))
        scatter = sp.csr_matrix((np.ones(n_el), (element_dofs[j], np.arange(n_el))),
                                shape=(n_nodes, n_el))
        blocks += scatter @ block.reshape(n_el, 81)
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

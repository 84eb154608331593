"""The symmetrising correction of the equilibrated stress (docs/theory.md, section 13.2).

The rows of sigma* are reconstructed one by one, so sigma* has a skew part of the order of the
error, and C_K ||skw sigma*|| costs about as much as the symmetric term. Adding to row r the
curl of a stream function phi_r in continuous P_(k+1) (curl phi = (d_2 phi, -d_1 phi)) keeps
everything the bound needs: curl P_(k+1) lies in RT_k, div curl phi = 0, and the normal trace
n . curl phi = d phi / d s vanishes on a facet where phi does. With phi = 0 on the facets where
sigma* n is prescribed (Gamma_N and Gamma_C), sigma* + curl phi equilibrates the same data, so
every phi keeps the bound; the one taken minimises

    ||C^{-1/2}(sym(sigma* + curl phi) - sigma_h)||^2 + w ||skw(sigma* + curl phi)||^2,

w = WEIGHT C_K^2: a symmetric positive definite system for the 2 dim P_(k+1) values of phi,
solved approximately (RTOL below). The element matrices come from reference-element data: on
an affine triangle the physical gradient is J^-T grad^, so every matrix is a reference tensor
contracted with J.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import LinearOperator, aslinearoperator, cg
from skfem.assembly import Dofs

from estimators.guaranteed.equilibration import Reconstruction
from estimators.guaranteed.patch_classes import Classes, equal_rows
from estimators.guaranteed.patch_data import SCALARS, Interior
from estimators.guaranteed.rt_reference import ReferenceRT, rt_moments

# w / C_K^2. The bound adds S + C_K K (S, K the two norms above); at the phi minimising it,
# the weight of the squares is w = C_K^2 S / (C_K K), measured 10 .. 20 on `paper` and `hertz`
# at P1, where S + C_K K is flat within 0.5 % for w / C_K^2 from 10 to 100.
WEIGHT = 20.0
# Every phi keeps the bound, so the minimisation need not be exact: at RTOL the objective is
# within 0.5 % of its least value (measured on `paper`, P1, 1.3e5 .. 2.1e6 unknowns, 21 .. 28
# iterations, independent of h; a direct solve of 2.1e6 took 16 s, these about 3 s).
RTOL = 1e-2
MAX_ITERATIONS = 500
_ROTATE = np.array([[0.0, 1.0], [-1.0, 0.0]])  # curl phi = _ROTATE grad phi


def density(lam: float, mu: float, weight: float) -> np.ndarray:
    """Q (2, 2, 2, 2) with q(T, S) = sum Q[r, c, s, d] T[r, c] S[s, d] = C^-1 sym T : sym S +
    weight (T_12 - T_21)(S_12 - S_21) / 2, the plane strain compliance of
    ``estimators.averaging.compliance_energy``."""
    unit = np.eye(4).reshape(4, 2, 2)
    sym = 0.5 * (unit + unit.transpose(0, 2, 1))
    trace = np.trace(sym, axis1=1, axis2=2)
    compliance = (np.einsum("arc,brc->ab", sym, sym)
                  - lam / (2 * (lam + mu)) * np.outer(trace, trace)) / (2 * mu)
    skew = unit[:, 0, 1] - unit[:, 1, 0]
    return (compliance + weight * np.outer(skew, skew) / 2).reshape(2, 2, 2, 2)


def stream_gradients(k: int, X: np.ndarray) -> np.ndarray:
    """The reference gradients (n_s, 2, nq) of the scalar P_(k+1) basis at the points X."""
    element = SCALARS[k + 1]()
    return np.array([element.lbasis(X, j)[1] for j in range(element.doflocs.shape[0])])


def curl_map(mesh) -> np.ndarray:
    """H (n_el, 2, 2) with curl phi = H grad^ phi^ on every element (grad = J^-T grad^)."""
    return np.einsum("cd,edn->nce", _ROTATE, mesh.mapping().invA)


def element_system(rt: ReferenceRT, Q: np.ndarray, residual: np.ndarray,
                   elements: np.ndarray | None = None):
    """The element matrices (n_el, 2 n_s, 2 n_s) of q(curl phi, curl chi) (of ``elements``
    only, if given) and the element vectors (n_el, 2 n_s) of -q(residual, curl chi) for
    residual (2, 2, n_el, nq) at the points of ``rt``; unknowns ordered (row, local P_(k+1)
    function)."""
    mesh, (X, W) = rt.mesh, rt.quadrature
    grad = stream_gradients(rt.elem.k, X)                              # (n_s, 2, nq)
    n_s, n_el = grad.shape[0], mesh.t.shape[1]
    H, det = curl_map(mesh), np.abs(mesh.mapping().detA)
    chosen = slice(None) if elements is None else elements
    Hc = H[chosen]
    QM = Q.transpose(0, 2, 1, 3).reshape(4, 4)                        # (r s, c d)
    HH = (Hc[:, :, None, :, None] * Hc[:, None, :, None, :]).reshape(-1, 4, 4)  # (c d, e f)
    coupling = np.matmul(QM, HH) * det[chosen][:, None, None]          # (n, r s, e f)
    reference = np.einsum("iep,jfp,p->efij", grad, grad, W).reshape(4, -1)
    matrices = (coupling.reshape(-1, 4) @ reference).reshape(-1, 2, 2, n_s, n_s)
    matrices = matrices.transpose(0, 1, 3, 2, 4)                       # (n, r, i, s, j)
    tested = (Q.reshape(4, 4).T @ residual.reshape(4, -1)).reshape(2, 2, n_el, -1)
    pulled = np.matmul(tested.transpose(2, 0, 3, 1), H[:, None])       # (n, s, p, e)
    weighted = np.einsum("iep,p->pei", grad, W).reshape(-1, n_s)
    vectors = -(pulled.reshape(n_el * 2, -1) @ weighted).reshape(n_el, 2, n_s) * det[:, None, None]
    return matrices.reshape(-1, 2 * n_s, 2 * n_s), vectors.reshape(n_el, 2 * n_s)


def curl_classes(mesh) -> Classes:
    """Elements with equal stream matrices: the matrices depend on the element only through
    |det J|^(1/2) J^-T, which translation and scaling leave alone (docs/theory.md, 13.2)."""
    scaled = curl_map(mesh) * np.sqrt(np.abs(mesh.mapping().detA))[:, None, None]
    return Classes.of_owners(equal_rows([scaled]))


@dataclass(frozen=True, eq=False)
class StreamElements:
    """The minimisation of the module docstring, element by element: ``vectors`` (n_el, m)
    for the unknowns ``index`` (n_el, m; row r's values at r n + node), ``free``, the values
    not pinned, and the matrices (n_classes, m, m) of the element ``classes``
    (``matrices`` gives them per element)."""

    class_matrices: np.ndarray
    vectors: np.ndarray
    index: np.ndarray
    free: np.ndarray
    classes: Classes

    @property
    def matrices(self) -> np.ndarray:
        """The element matrices (n_el, m, m)."""
        return self.class_matrices[self.classes.of]

    def assembled(self, local: np.ndarray) -> np.ndarray:
        """The global vector of element vectors (n_el, m), 0 on pinned values."""
        return np.bincount(self.index.ravel(), local.ravel(), minlength=self.free.size) * self.free

    @property
    def rhs(self) -> np.ndarray:
        return self.assembled(self.vectors)


@dataclass(frozen=True, eq=False)
class StreamSystem:
    """The minimisation of the module docstring for phi (row r's values at r n + node):
    ``operator`` its matrix on the free values (element matrices, float32 products), ``rhs``,
    ``blocks`` the inverse 2 x 2 node blocks (0 on pinned values) and ``free``."""

    operator: LinearOperator
    rhs: np.ndarray
    blocks: sp.csr_matrix
    free: np.ndarray


def stream_elements(rt: ReferenceRT, residual: np.ndarray, prescribed: np.ndarray,
                    lame: tuple[float, float], korn: float) -> StreamElements:
    """The element data of the module docstring for the residual sigma* - sigma_h (2, 2, n_el,
    nq) at the points of ``rt``, phi = 0 on the ``prescribed`` facets (one value pinned per
    row if there are none: curl ignores constants)."""
    dofs = Dofs(rt.mesh, SCALARS[rt.elem.k + 1]())
    n = dofs.N
    classes = curl_classes(rt.mesh)
    matrices, vectors = element_system(rt, density(*lame, WEIGHT * korn**2), residual,
                                       classes.first)
    index = np.vstack([dofs.element_dofs, dofs.element_dofs + n]).T
    pinned = (dofs.get_facet_dofs(prescribed).all() if prescribed.size
              else np.zeros(1, dtype=np.int64))
    free = np.ones(2 * n, dtype=bool)
    free[np.concatenate([pinned, pinned + n])] = False
    return StreamElements(matrices, vectors, index, free, classes)


def stream_system(elements: StreamElements) -> StreamSystem:
    """The matrix-free system of ``elements``: gathered class by class (one matrix product
    per class), summed back by a sparse scatter matrix (4x faster than ``bincount`` at 2e6
    values, measured on `paper`, P1, 526 338 DOFs)."""
    single = elements.class_matrices.astype(np.float32)  # any phi keeps the bound: float32
    classes, free = elements.classes, elements.free
    index = elements.index[classes.order]
    scatter = sp.csr_matrix((np.ones(index.size, dtype=np.float32),
                             (index.ravel(), np.arange(index.size))),
                            shape=(free.size, index.size))

    def apply(x: np.ndarray) -> np.ndarray:
        local = (x * free).astype(np.float32)[index]
        return (scatter @ classes.products(single, local).ravel()).astype(float) * free

    operator = LinearOperator((free.size, free.size), matvec=apply, dtype=float)
    return StreamSystem(operator, elements.rhs, node_blocks(elements), free)


def stream_function(rt: ReferenceRT, residual: np.ndarray, prescribed: np.ndarray,
                    lame: tuple[float, float], korn: float) -> np.ndarray:
    """phi (2, dim P_(k+1)) of the module docstring (``stream_elements``' arguments), by
    conjugate gradients preconditioned by the node blocks, to RTOL."""
    system = stream_system(stream_elements(rt, residual, prescribed, lame, korn))
    phi, _ = cg(system.operator, system.rhs, rtol=RTOL, maxiter=MAX_ITERATIONS,
                M=aslinearoperator(system.blocks))
    return (phi * system.free).reshape(2, -1)


def node_blocks(elements: StreamElements) -> sp.csr_matrix:
    """The inverse of the 2 x 2 blocks of the two rows' values at each node (the skew weight
    couples them), 0 on pinned values: CG needs about 30 % fewer iterations than with the
    diagonal alone (measured on `paper`, P1, 1.3e5 unknowns: 28 against 40)."""
    index, free, matrices = elements.index, elements.free, elements.class_matrices
    n, n_s = free.size // 2, index.shape[1] // 2
    local = np.arange(n_s)

    def gathered(values):
        return np.bincount(index[:, :n_s].ravel(), values[elements.classes.of].ravel(),
                           minlength=n)

    a = gathered(matrices[:, local, local])
    d = gathered(matrices[:, n_s + local, n_s + local])
    c = gathered(matrices[:, local, n_s + local])
    kept = free[:n]
    scale = kept / np.where(kept, a * d - c * c, 1.0)
    node = np.arange(n)
    rows = np.concatenate([node, node, node + n, node + n])
    cols = np.concatenate([node, node + n, node, node + n])
    values = np.concatenate([d, -c, -c, a]) * np.tile(scale, 4)
    return sp.csr_matrix((values, (rows, cols)), shape=(2 * n, 2 * n))


def curl_values(rt: ReferenceRT, phi: np.ndarray) -> np.ndarray:
    """curl phi_r as row r (2, 2, n_el, nq) at the points of ``rt``."""
    mesh = rt.mesh
    element = SCALARS[rt.elem.k + 1]()
    local = phi[:, Dofs(mesh, element).element_dofs]                    # (2, n_s, n_el)
    grad = stream_gradients(rt.elem.k, rt.quadrature[0])
    return np.einsum("nce,rin,iep->rcnp", curl_map(mesh), local, grad)


def rt_dofs(rt: ReferenceRT, interior: Interior, values: np.ndarray) -> np.ndarray:
    """The RT_k DOFs (d, N) of fields (d, d, n_el, nq) that lie in RT_k row by row: the
    element-wise L2 projection with ``interior``'s mass matrices, one inverse per class of
    elements, exact for such fields (neighbours agree on a shared facet's DOFs to round-off)."""
    X, W = rt.quadrature
    d = values.shape[0]
    moments = rt_moments(rt.mesh, rt.elem.k, X, W, values, np.ones((1, W.size)))[:, 0]
    classes = interior.classes
    local = np.empty((moments.shape[0], moments.shape[2], d))         # (n_el, n_rt, d)
    local[classes.order] = classes.products(np.linalg.inv(interior.class_mass),
                                            moments[classes.order].transpose(0, 2, 1))
    out = np.zeros((d, rt.N))
    out[:, rt.element_dofs.T] = local.transpose(2, 0, 1)
    return out


def symmetrised(rec: Reconstruction, interior: Interior, prescribed: np.ndarray,
                lame: tuple[float, float], korn: float) -> Reconstruction:
    """``rec`` plus the curl of the minimising stream functions (module docstring), with
    its RT_k DOFs; ``prescribed`` the facets where sigma* n is prescribed."""
    rt = rec.basis
    phi = stream_function(rt, rec.values - interior.sigma_h, prescribed, lame, korn)
    correction = curl_values(rt, phi)
    return replace(rec, dofs=rec.dofs + rt_dofs(rt, interior, correction),
                   values=rec.values + correction)

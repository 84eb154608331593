"""The element integrals of the vertex-patch problems from reference-element data
(docs/theory.md, section 13.2).

On an affine triangle T = F(T^), F(x^) = J x^ + b, the RT_k functions are the contravariant
Piola maps phi_j = o_j J phi^_j / |det J| (o_j = +-1 the facet orientation, 1 inside), their
divergences o_j div^ phi^_j / |det J|, and dx = |det J| dx^. Every integral of the patch
problems is then a small reference tensor, computed once, contracted with J per element:

    (phi_j, phi_l)_T         = o_j o_l / |det J| sum_cd (J'J)_cd  int^ phi^_jc phi^_ld,
    (div phi_j, q_l)_T       = o_j int^ div^ phi^_j q^_l,
    (phi_j, psi_a sigma_r)_T = o_j sum_c int^ phi^_jc psi^_a (J' sigma_r)_c,

with sigma_h sampled at the reference quadrature points, so that the last is one matrix
product over all elements. No basis function is evaluated on the physical elements.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from skfem import Basis, ElementTriP1
from skfem.assembly import Dofs
from skfem.quadrature import get_quadrature
from skfem.refdom import RefTri

from estimators.raviart_thomas import ElementTriRTk


@dataclass(frozen=True, eq=False)
class ReferenceRT:
    """RT_k on a triangle mesh with a quadrature rule, without basis values on the elements:
    its DOF numbering (scikit-fem's, ``element_dofs`` and ``N``), the rule (X, W), dx and the
    points in physical coordinates. ``basis()`` builds scikit-fem's Basis when a caller needs
    one (interpolation in tests)."""

    mesh: object
    elem: ElementTriRTk
    quadrature: tuple[np.ndarray, np.ndarray]
    element_dofs: np.ndarray
    N: int

    @classmethod
    def build(cls, mesh, k: int, intorder: int) -> ReferenceRT:
        elem = ElementTriRTk(k)
        dofs = Dofs(mesh, elem)
        return cls(mesh, elem, get_quadrature(RefTri, intorder), dofs.element_dofs, dofs.N)

    @property
    def dx(self) -> np.ndarray:
        return np.abs(self.mesh.mapping().detA)[:, None] * self.quadrature[1][None, :]

    def global_coordinates(self) -> np.ndarray:
        return self.mesh.mapping().F(self.quadrature[0])

    def basis(self) -> Basis:
        return Basis(self.mesh, self.elem, quadrature=self.quadrature)

    def values(self, dofs: np.ndarray) -> np.ndarray:
        """The values (r, 2, n_el, nq) of fields with RT DOFs ``dofs`` (r, N) at the points:
        o_j J phi^_j / |det J| summed with the element's DOF values."""
        phi, _ = reference_rt(self.elem.k, self.quadrature[0])
        reference = np.einsum("rje,jcp->rcep", self._signed(dofs, slice(None)), phi,
                              optimize=True)
        return self._piola(reference, slice(None))

    def values_at(self, dofs: np.ndarray, x: np.ndarray, cells: np.ndarray) -> np.ndarray:
        """The values (r, 2, n, nq) of fields with RT DOFs ``dofs`` (r, N) at physical points
        x (2, n, nq), row i of x in element cells[i] (the Piola map of ``values``)."""
        n, nq = x.shape[1:]
        X = np.asarray(self.mesh.mapping().invF(x, tind=cells)).reshape(2, -1)
        n_rt = self.element_dofs.shape[0]
        phi = np.array([self.elem.lbasis(X, j)[0] for j in range(n_rt)]).reshape(n_rt, 2, n, nq)
        reference = np.einsum("rjn,jcnp->rcnp", self._signed(dofs, cells), phi)
        return self._piola(reference, cells)

    def _signed(self, dofs: np.ndarray, cells) -> np.ndarray:
        """o_j times the DOF values (r, n_rt, n) of the elements ``cells``."""
        n_rt = self.element_dofs.shape[0]
        return (dofs[:, self.element_dofs[:, cells]]
                * orientations(self.mesh, n_rt, self.elem.k)[cells].T[None])

    def _piola(self, reference: np.ndarray, cells) -> np.ndarray:
        """J v^ / |det J| of reference vectors (r, 2, n, nq) on the elements ``cells``."""
        mapping = self.mesh.mapping()
        return np.einsum("icn,rcnp->rinp", mapping.A[:, :, cells], reference) / np.abs(
            mapping.detA[cells])[None, None, :, None]


def reference_rt(k: int, X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """RT_k reference values (n_rt, 2, nq) and divergences (n_rt, nq) at the points X."""
    element = ElementTriRTk(k)
    pairs = [element.lbasis(X, j) for j in range(element.doflocs.shape[0])]
    return np.array([p[0] for p in pairs]), np.array([p[1] for p in pairs])


def scalar_values(element, X: np.ndarray) -> np.ndarray:
    """The reference basis (n, nq) of a scalar Lagrange element at the points X."""
    return np.array([element.lbasis(X, j)[0] for j in range(element.doflocs.shape[0])])


def orientations(mesh, n_rt: int, k: int) -> np.ndarray:
    """o_j per element (n_el, n_rt): -1 on a facet DOF whose facet's first element is another
    one (scikit-fem's ``ElementHdiv.orient``), +1 otherwise."""
    own = mesh.f2t[0, mesh.t2f] == np.arange(mesh.t.shape[1])[None, :]   # (3, n_el)
    signs = np.ones((mesh.t.shape[1], n_rt))
    signs[:, :3 * (k + 1)] = np.repeat(np.where(own, 1.0, -1.0).T, k + 1, axis=1)
    return signs


def element_matrices(mesh, k: int, X: np.ndarray, W: np.ndarray, dg: np.ndarray,
                     elements: np.ndarray | None = None):
    """The RT_k mass (n_el, n_rt, n_rt) and divergence (n_el, n_dg, n_rt) matrices for the
    reference basis ``dg`` (n_dg, nq) at the rule (X, W), of the ``elements`` only if given."""
    mapping = mesh.mapping()
    chosen = slice(None) if elements is None else elements
    J, det = mapping.A[:, :, chosen], np.abs(mapping.detA)[chosen]     # (2, 2, n), (n,)
    phi, div = reference_rt(k, X)
    o = orientations(mesh, phi.shape[0], k)[chosen]
    gram = np.einsum("ice,ide->cde", J, J)                             # J'J
    mass_ref = np.einsum("jcp,ldp,p->cdjl", phi, phi, W)
    n_rt = phi.shape[0]
    mass = (gram.reshape(4, -1).T @ mass_ref.reshape(4, -1)).reshape(-1, n_rt, n_rt)
    mass /= det[:, None, None]
    mass *= o[:, :, None] * o[:, None, :]
    divergence = np.einsum("jp,lp,p->lj", div, dg, W)[None] * o[:, None, :]
    return mass, divergence


def patch_rhs(mesh, k: int, X: np.ndarray, W: np.ndarray, dg: np.ndarray,
              sigma_h: np.ndarray, hat_gradients: np.ndarray):
    """r = (phi_j, psi_a sigma_h row r) (n_el, 3, 2, n_rt) and c = (sigma_h grad psi_a, q_l)
    (n_el, 3, 2, n_dg) for sigma_h (2, 2, n_el, nq) at the reference points X and the
    barycentric gradients (3, 2, n_el)."""
    n_el = mesh.t.shape[1]
    rhs = rt_moments(mesh, k, X, W, sigma_h, scalar_values(ElementTriP1(), X))
    samples = sigma_h.transpose(2, 0, 1, 3).reshape(n_el * 4, -1)     # (e r k, p)
    tested = (samples @ (dg * W).T).reshape(n_el, 2, 2, -1)           # e r k l
    det = np.abs(mesh.mapping().detA)
    data = np.einsum("ake,erkl->earl", hat_gradients, tested) * det[:, None, None, None]
    return rhs, data


def rt_moments(mesh, k: int, X: np.ndarray, W: np.ndarray, fields: np.ndarray,
               weights: np.ndarray) -> np.ndarray:
    """(phi_j, w_a f_r)_T (n_el, n_w, 2, n_rt) for fields f (2, 2, n_el, nq), row r, at the
    reference points X and reference weights w (n_w, nq): one matrix product of J' f_r with
    a reference tensor."""
    J = mesh.mapping().A
    phi, _ = reference_rt(k, X)
    n_rt, n_el, n_w = phi.shape[0], mesh.t.shape[1], weights.shape[0]
    o = orientations(mesh, n_rt, k)
    pulled = np.einsum("kce,rkep->ercp", J, fields).reshape(n_el * 2, -1)     # J' f row
    weighted = np.einsum("jcp,ap,p->cpaj", phi, weights, W).reshape(pulled.shape[1], -1)
    return ((pulled @ weighted).reshape(n_el, 2, n_w, n_rt).transpose(0, 2, 1, 3)
            * o[:, None, None])


def summed_matrix(blocks: np.ndarray, index: np.ndarray, size: int) -> sp.csr_matrix:
    """The size x size sparse sum of element matrices ``blocks`` (n_el, m, m) on the global
    unknowns ``index`` (n_el, m)."""
    m = index.shape[1]
    rows, cols = np.repeat(index, m, axis=1), np.tile(index, (1, m))
    return sp.csr_matrix((blocks.ravel(), (rows.ravel(), cols.ravel())), shape=(size, size))

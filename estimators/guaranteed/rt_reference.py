"""The element integrals of the vertex-patch problems from reference-element data
(docs/theory.md, section 13.2).

On an affine triangle or tetrahedron T = F(T^), F(x^) = J x^ + b, the RT_k functions are the
contravariant Piola maps phi_j = o_j J phi^_j / |det J| (o_j = +-1 the facet orientation, 1
inside), their divergences o_j div^ phi^_j / |det J|, and dx = |det J| dx^. Every integral of
the patch problems is then a small reference tensor, computed once, contracted with J per element:

    (phi_j, phi_l)_T         = o_j o_l / |det J| sum_cd (J'J)_cd  int^ phi^_jc phi^_ld,
    (div phi_j, q_l)_T       = o_j int^ div^ phi^_j q^_l,
    (phi_j, psi_a sigma_r)_T = o_j sum_c int^ phi^_jc psi^_a (J' sigma_r)_c,

with sigma_h sampled at the reference quadrature points, so that the last is one matrix
product over all elements. No basis function is evaluated on the physical elements.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from skfem import Basis, ElementTetP1, ElementTriP1
from skfem.assembly import Dofs
from skfem.element import ElementHdiv
from skfem.quadrature import get_quadrature
from skfem.refdom import RefTet, RefTri

from estimators.guaranteed.raviart_thomas import ElementTriRTk
from estimators.guaranteed.raviart_thomas_tet import ElementTetRTk

REFERENCE = {2: RefTri, 3: RefTet}
HATS = {2: ElementTriP1, 3: ElementTetP1}
# the facet of scikit-fem's reference simplex opposite each vertex: triangles' facets are
# (0, 1), (1, 2), (0, 2), tetrahedra's (0, 1, 2), (0, 1, 3), (0, 2, 3), (1, 2, 3)
OPPOSITE_FACET = {2: np.array([1, 2, 0]), 3: np.array([3, 2, 1, 0])}


@functools.cache
def rt_element(k: int, dim: int) -> ElementHdiv:
    """RT_k on triangles (dim 2) or tetrahedra (dim 3); built once (its nodal basis is an
    inverse)."""
    return {2: ElementTriRTk, 3: ElementTetRTk}[dim](k)


def facet_dof_count(k: int, dim: int) -> int:
    """RT_k DOFs per facet: dim P_k on a facet (a segment in 2D, a triangle in 3D)."""
    return math.comb(k + dim - 1, dim - 1)


@dataclass(frozen=True, eq=False)
class ReferenceRT:
    """RT_k on a triangle or (sorted, ``estimators.guaranteed.raviart_thomas_tet``) tetrahedron mesh
    with a quadrature rule, without basis values on the elements:
    its DOF numbering (scikit-fem's, ``element_dofs`` and ``N``), the rule (X, W), dx and the
    points in physical coordinates. ``basis()`` builds scikit-fem's Basis when a caller needs
    one (interpolation in tests)."""

    mesh: object
    elem: ElementHdiv
    quadrature: tuple[np.ndarray, np.ndarray]
    element_dofs: np.ndarray
    N: int

    @classmethod
    def build(cls, mesh, k: int, intorder: int) -> ReferenceRT:
        dim = mesh.dim()
        elem = rt_element(k, dim)
        dofs = Dofs(mesh, elem)
        return cls(mesh, elem, get_quadrature(REFERENCE[dim], intorder), dofs.element_dofs,
                   dofs.N)

    @property
    def dx(self) -> np.ndarray:
        return np.abs(self.mesh.mapping().detA)[:, None] * self.quadrature[1][None, :]

    def global_coordinates(self) -> np.ndarray:
        return self.mesh.mapping().F(self.quadrature[0])

    def basis(self) -> Basis:
        return Basis(self.mesh, self.elem, quadrature=self.quadrature)

    def values(self, dofs: np.ndarray) -> np.ndarray:
        """The values (r, d, n_el, nq) of fields with RT DOFs ``dofs`` (r, N) at the points:
        o_j J phi^_j / |det J| summed with the element's DOF values."""
        phi, _ = reference_rt(self.elem.k, self.quadrature[0])
        reference = np.einsum("rje,jcp->rcep", self._signed(dofs, slice(None)), phi,
                              optimize=True)
        return self._piola(reference, slice(None))

    def values_at(self, dofs: np.ndarray, x: np.ndarray, cells: np.ndarray,
                  reference: np.ndarray | None = None) -> np.ndarray:
        """The values (r, d, n, nq) of fields with RT DOFs ``dofs`` (r, N) at physical points
        x (d, n, nq), row i of x in element cells[i] (the Piola map of ``values``); with
        ``reference`` (d, nq), the reference points that x are the images of in every cell
        (the basis is then evaluated once, not at every point)."""
        if reference is not None:
            phi, _ = reference_rt(self.elem.k, reference)                   # (n_rt, d, nq)
            return self._piola(np.einsum("rjn,jcp->rcnp", self._signed(dofs, cells), phi),
                               cells)
        d, n, nq = x.shape
        X = np.asarray(self.mesh.mapping().invF(x, tind=cells)).reshape(d, -1)
        n_rt = self.element_dofs.shape[0]
        phi = np.array([self.elem.lbasis(X, j)[0] for j in range(n_rt)]).reshape(n_rt, d, n, nq)
        values = np.einsum("rjn,jcnp->rcnp", self._signed(dofs, cells), phi)
        return self._piola(values, cells)

    def _signed(self, dofs: np.ndarray, cells) -> np.ndarray:
        """o_j times the DOF values (r, n_rt, n) of the elements ``cells``."""
        n_rt = self.element_dofs.shape[0]
        return (dofs[:, self.element_dofs[:, cells]]
                * orientations(self.mesh, n_rt, self.elem.k)[cells].T[None])

    def _piola(self, reference: np.ndarray, cells) -> np.ndarray:
        """J v^ / |det J| of reference vectors (r, d, n, nq) on the elements ``cells``."""
        mapping = self.mesh.mapping()
        return np.einsum("icn,rcnp->rinp", mapping.A[:, :, cells], reference) / np.abs(
            mapping.detA[cells])[None, None, :, None]


def reference_rt(k: int, X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """RT_k reference values (n_rt, d, nq) and divergences (n_rt, nq) at the points X (d, nq)."""
    element = rt_element(k, X.shape[0])
    pairs = [element.lbasis(X, j) for j in range(element.doflocs.shape[0])]
    return np.array([p[0] for p in pairs]), np.array([p[1] for p in pairs])


def scalar_values(element, X: np.ndarray) -> np.ndarray:
    """The reference basis (n, nq) of a scalar Lagrange element at the points X."""
    return np.array([element.lbasis(X, j)[0] for j in range(element.doflocs.shape[0])])


def orientations(mesh, n_rt: int, k: int) -> np.ndarray:
    """o_j per element (n_el, n_rt): -1 on a facet DOF whose facet's first element is another
    one (scikit-fem's ``ElementHdiv.orient``), +1 otherwise."""
    own = mesh.f2t[0, mesh.t2f] == np.arange(mesh.t.shape[1])[None, :]   # (d + 1, n_el)
    per_facet = facet_dof_count(k, mesh.dim())
    signs = np.ones((mesh.t.shape[1], n_rt))
    signs[:, :own.shape[0] * per_facet] = np.repeat(np.where(own, 1.0, -1.0).T, per_facet,
                                                    axis=1)
    return signs


def element_matrices(mesh, k: int, X: np.ndarray, W: np.ndarray, dg: np.ndarray,
                     elements: np.ndarray | None = None):
    """The RT_k mass (n_el, n_rt, n_rt) and divergence (n_el, n_dg, n_rt) matrices for the
    reference basis ``dg`` (n_dg, nq) at the rule (X, W), of the ``elements`` only if given."""
    mapping = mesh.mapping()
    chosen = slice(None) if elements is None else elements
    J, det = mapping.A[:, :, chosen], np.abs(mapping.detA)[chosen]     # (d, d, n), (n,)
    phi, div = reference_rt(k, X)
    o = orientations(mesh, phi.shape[0], k)[chosen]
    gram = np.einsum("ice,ide->cde", J, J)                             # J'J
    mass_ref = np.einsum("jcp,ldp,p->cdjl", phi, phi, W)
    n_rt = phi.shape[0]
    d2 = J.shape[0] ** 2
    mass = (gram.reshape(d2, -1).T @ mass_ref.reshape(d2, -1)).reshape(-1, n_rt, n_rt)
    mass /= det[:, None, None]
    mass *= o[:, :, None] * o[:, None, :]
    divergence = np.einsum("jp,lp,p->lj", div, dg, W)[None] * o[:, None, :]
    return mass, divergence


def patch_rhs(mesh, k: int, X: np.ndarray, W: np.ndarray, dg: np.ndarray,
              sigma_h: np.ndarray, hat_gradients: np.ndarray):
    """r = (phi_j, psi_a sigma_h row r) (n_el, d + 1, d, n_rt) and c = (sigma_h grad psi_a,
    q_l) (n_el, d + 1, d, n_dg) for sigma_h (d, d, n_el, nq) at the reference points X and the
    barycentric gradients (d + 1, d, n_el)."""
    n_el, d = mesh.t.shape[1], X.shape[0]
    rhs = rt_moments(mesh, k, X, W, sigma_h, scalar_values(HATS[d](), X))
    samples = sigma_h.transpose(2, 0, 1, 3).reshape(n_el * d * d, -1)   # (e r k, p)
    tested = (samples @ (dg * W).T).reshape(n_el, d, d, -1)             # e r k l
    det = np.abs(mesh.mapping().detA)
    data = np.einsum("ake,erkl->earl", hat_gradients, tested) * det[:, None, None, None]
    return rhs, data


def rt_moments(mesh, k: int, X: np.ndarray, W: np.ndarray, fields: np.ndarray,
               weights: np.ndarray) -> np.ndarray:
    """(phi_j, w_a f_r)_T (n_el, n_w, d, n_rt) for fields f (d, d, n_el, nq), row r, at the
    reference points X and reference weights w (n_w, nq): one matrix product of J' f_r with
    a reference tensor."""
    J = mesh.mapping().A
    phi, _ = reference_rt(k, X)
    n_rt, n_el, n_w, d = phi.shape[0], mesh.t.shape[1], weights.shape[0], X.shape[0]
    o = orientations(mesh, n_rt, k)
    pulled = np.einsum("kce,rkep->ercp", J, fields).reshape(n_el * d, -1)     # J' f row
    weighted = np.einsum("jcp,ap,p->cpaj", phi, weights, W).reshape(pulled.shape[1], -1)
    return ((pulled @ weighted).reshape(n_el, d, n_w, n_rt).transpose(0, 2, 1, 3)
            * o[:, None, None])


def summed_matrix(blocks: np.ndarray, index: np.ndarray, size: int) -> sp.csr_matrix:
    """The size x size sparse sum of element matrices ``blocks`` (n_el, m, m) on the global
    unknowns ``index`` (n_el, m)."""
    m = index.shape[1]
    rows, cols = np.repeat(index, m, axis=1), np.tile(index, (1, m))
    return sp.csr_matrix((blocks.ravel(), (rows.ravel(), cols.ravel())), shape=(size, size))

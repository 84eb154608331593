"""A reference simplex refined into sub-simplices, with the lowest-order Raviart-Thomas
functions of its inner faces (docs/theory.md, section 13.2, "Where f jumps, element by
element"): the same on every element, mapped by the element's Piola transform."""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from math import factorial

import numpy as np
from skfem.quadrature import get_quadrature

from formulations.cells.load import children, mapped_rule


@dataclass(frozen=True, eq=False)
class SubSimplices:
    """The reference simplex ``refdom`` (scikit-fem's ``RefTri`` or ``RefTet``) refined
    ``levels`` times (the load rule's red refinement): ``corners`` (n_sub, d + 1, d),
    ``face`` (n_sub, d + 1) the inner face opposite each local vertex (-1 on the simplex's
    boundary), ``sign`` (n_sub, d + 1) +1 where the sub-simplex is the face's first, the
    signed incidence B (n_sub, n_inner) and C (d, d, n_inner, n_inner), C[p, q, F, G] = int
    phi_F,p phi_G,q, phi_F the RT_0 function of unit flux across F from its first
    sub-simplex to its second."""

    refdom: type
    corners: np.ndarray
    face: np.ndarray
    sign: np.ndarray
    incidence: np.ndarray
    tensors: np.ndarray

    @property
    def volume(self) -> float:
        """The measure of one sub-simplex (they are all alike)."""
        edges = self.corners[0, 1:] - self.corners[0, :1]
        return float(abs(np.linalg.det(edges)) / factorial(edges.shape[0]))

    def local_rt0(self, X: np.ndarray) -> np.ndarray:
        """phi (d + 1, d, n_sub, nq) at the points X (d, n_sub, nq) of every sub-simplex:
        sign (x - p_j) / (d |S|), p_j the vertex opposite local face j (unit outward flux
        across face j, none across the others; times ``sign``)."""
        d = X.shape[0]
        phi = (X[None] - self.corners.transpose(1, 2, 0)[:, :, :, None]) / (d * self.volume)
        return phi * self.sign.T[:, None, :, None]

    def values(self, coefficients: np.ndarray, X: np.ndarray) -> np.ndarray:
        """sum_F c_F phi_F (n, r, d, n_sub, nq) at the points X (d, n_sub, nq) for the
        coefficients (n, n_inner, r) of the inner faces."""
        inner = self.face >= 0
        gathered = coefficients[:, np.where(inner, self.face, 0)] * inner[None, :, :, None]
        return np.einsum("nsjr,jcsq->nrcsq", gathered, self.local_rt0(X))


@lru_cache(maxsize=4)
def sub_simplices(refdom: type, levels: int) -> SubSimplices:
    """The refined reference simplex and its RT_0 data (``SubSimplices``)."""
    d = refdom.dim()
    corners = refdom.p.T[None]
    for _ in range(levels):
        corners = children(corners)
    n_sub = corners.shape[0]
    ids = np.unique(np.round(corners.reshape(-1, d) * 2**levels).astype(np.int64), axis=0,
                    return_inverse=True)[1].reshape(n_sub, d + 1)
    opposite = [np.delete(np.arange(d + 1), j) for j in range(d + 1)]
    faces = np.sort(np.stack([ids[:, o] for o in opposite], axis=1), axis=2)  # (n_sub, d+1, d)
    _, face, counts = np.unique(faces.reshape(-1, d), axis=0, return_inverse=True,
                                return_counts=True)
    face = face.reshape(n_sub, d + 1)
    first = np.full(counts.size, n_sub)
    np.minimum.at(first, face, np.repeat(np.arange(n_sub), d + 1).reshape(n_sub, d + 1))
    sign = np.where(first[face] == np.arange(n_sub)[:, None], 1.0, -1.0)
    inner = counts[face] == 2
    number = np.cumsum(counts == 2) - 1
    face = np.where(inner, number[face], -1)
    incidence = np.zeros((n_sub, int((counts == 2).sum())))
    rows, cols = np.nonzero(inner)
    incidence[rows, face[rows, cols]] = sign[rows, cols]
    sub = SubSimplices(refdom, corners, face, sign, incidence, np.zeros(0))
    return SubSimplices(refdom, corners, face, sign, incidence, _rt0_tensors(sub))


def _rt0_tensors(sub: SubSimplices) -> np.ndarray:
    """C of ``SubSimplices``, integrated exactly (degree 2) sub-simplex by sub-simplex."""
    n_inner = sub.incidence.shape[1]
    X, W = mapped_rule(sub.corners, get_quadrature(sub.refdom, 2))
    values = sub.values(np.eye(n_inner)[None], X)[0]                    # (F, d, n_sub, nq)
    return np.einsum("Fpsx,Gqsx,sx->pqFG", values, values, W)

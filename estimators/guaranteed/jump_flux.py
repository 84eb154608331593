"""The oscillation of a body force that jumps inside elements, bounded element by element with
a lowest-order Raviart-Thomas flux on sub-simplices (docs/theory.md, section 13.2, "Where f
jumps, element by element"); used on tetrahedra.

On a rough element T (one the load rule refines, ``formulations.cells.load``), r = f - Pi_k f is
O(1) and (h_T / pi) ||r||_T is several times its dual norm. T's reference simplex is refined
SUB_LEVELS times into sub-simplices S (the load rule's red refinement, mapped), and

    r = r_0 + r_1,   r_0 = (1/|S|) int_S r on each S,   r_1 = r - r_0.

r_0 is piecewise constant with zero mean on T, so a tau with rows in RT_0(S), tau . n = 0 on
the boundary of T and div tau = r_0 exists: (r_0, v)_T = -(tau, grad v)_T. r_1 has zero mean
on every S: (r_1, v)_S <= (h_S / pi) ||r_1||_S ||grad v||_S (Payne-Weinberger). So

    (r, v)_T <= osc_T ||grad v||_T,   osc_T = ||tau||_T + (sum_S (h_S / pi)^2 ||r_1||_S^2)^(1/2),

which replaces (h_T / pi) ||r||_T in ``estimators.guaranteed.oscillation``. Of these tau the one of
least L2 norm is taken: ||tau||_T^2 = m^T (B M^-1 B^T)^-1 m per row, with m the moments int_S r_0, B
the signed face-to-sub-simplex incidence (the same on every element) and M the RT_0 mass matrix,
which depends on T only through J^T J / |det J| (Piola). Inside sigma* (``combined``: A takes
sigma* - tau on T) only the remainder stays in osc_T. Where f is smooth the same bound with
SMOOTH_LEVELS is 2.3x below (h_T / pi) ||r||_T.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from skfem.quadrature import get_quadrature

from estimators.averaging import compliance_energy
from estimators.guaranteed.jump_equilibration import rough_elements
from estimators.guaranteed.patch_data import scalar_lagrange
from estimators.guaranteed.rt_reference import scalar_values
from estimators.guaranteed.sub_simplices import SubSimplices, sub_simplices
from formulations.cells.load import mapped_rule

SUB_LEVELS = 2  # 8^2 = 64 sub-tetrahedra per rough element
# where f is smooth, 8 sub-tetrahedra: (sum osc_T^2)^(1/2) 2.3x below Poincare's on T in a
# 26th of the time of 64 (docs/theory.md, 13.2, "Where f jumps, element by element")
SMOOTH_LEVELS = 1
RULE_DEGREE = 5  # on each sub-simplex; scikit-fem's degree-5 rules have positive weights
CHUNK = 2000  # elements per batch
# rules with positive weights exact for the squares of sigma* - tau (scikit-fem's tetrahedron
# rules of degree 3 and 4 have a negative weight)
GAP_DEGREE = {1: 2, 2: 5}


@dataclass(frozen=True, eq=False)
class FluxOscillation:
    """Per element of ``elements`` (the rough ones, or those asked for): ||tau||_T^2
    (``flux``), sum_S (h_S / pi)^2 ||r_1||_S^2 (``remainder``) and, if ``combined``,
    ||C^-1/2 sym(g - tau)||_T^2 (``symmetric``) and ||skw(g - tau)||_T^2 (``skew``) for the
    stress gap g = sigma* - sigma_h; ``divergence_defect`` the largest |sum_S m_S| over the
    elements relative to the largest int_T |f| (round-off: the moments have zero sum on every
    element)."""

    elements: np.ndarray
    flux: np.ndarray
    remainder: np.ndarray
    divergence_defect: float
    symmetric: np.ndarray | None = None
    skew: np.ndarray | None = None

    @property
    def combined(self) -> bool:
        """tau is inside sigma* (its terms replace sigma*'s on the rough elements)."""
        return self.symmetric is not None

    @property
    def osc_squares(self) -> np.ndarray:
        """osc_T^2 per rough element (module docstring): the remainder's alone if tau is
        inside sigma*."""
        if self.combined:
            return self.remainder
        return (np.sqrt(self.flux) + np.sqrt(self.remainder)) ** 2


def flux_oscillation(mesh, body_force, k: int, levels: int = SUB_LEVELS, gap=None,
                     lame: tuple[float, float] | None = None,
                     elements: np.ndarray | None = None) -> FluxOscillation | None:
    """The terms of the module docstring on the rough elements of ``mesh`` (or on
    ``elements``) for sigma* with divergence in P_k (None if there are none, or no f). With
    ``gap`` (sigma* - sigma_h (d, d, n, nq) at points x (d, n, nq) of elements ``cells``,
    the images of the reference points X (d, nq): ``gap(x, cells, X)``) and ``lame``, tau
    goes inside sigma*: the terms of sigma* - tau are ``combined``."""
    if (gap is None) != (lame is None):
        raise ValueError("flux_oscillation: gap and lame go together (got "
                         f"gap={'set' if gap is not None else None}, lame={lame})")
    if body_force is None:
        return None
    rough = rough_elements(mesh, body_force, k) if elements is None else np.asarray(elements)
    if rough.size == 0:
        return None
    parts = [_chunk_terms(mesh, rough[s:s + CHUNK], body_force, k, levels, gap, lame)
             for s in range(0, rough.size, CHUNK)]
    flux, remainder, missed, scale, symmetric, skew = (
        None if parts[0][i] is None else np.concatenate([p[i] for p in parts])
        for i in range(6))
    defect = missed.max() / max(scale.max(), np.finfo(float).tiny)
    return FluxOscillation(elements=rough, flux=flux, remainder=remainder,
                           divergence_defect=float(defect), symmetric=symmetric,
                           skew=skew)


def _chunk_terms(mesh, cells, body_force, k: int, levels: int, gap, lame):
    """flux, remainder, |sum_S m_S| and int_T |f| (largest over the rows) and, with
    ``gap``, the terms of sigma* - tau (``FluxOscillation``) on ``cells``."""
    finest = sub_simplices(mesh.elem.refdom, levels)
    moments, squares, scale = _sub_moments(mesh, cells, body_force, k, finest)
    A = mesh.mapping().A[:, :, cells].transpose(2, 0, 1)                # (n, d, d)
    det = np.abs(np.linalg.det(A))
    r_1 = np.clip(squares - (moments**2).sum(axis=2) / (det[:, None] * finest.volume), 0.0,
                  None)
    remainder = ((_sub_diameters(A, finest) / np.pi) ** 2 * r_1).sum(axis=1)
    flux, coefficients = _least_flux(A, moments, finest)
    missed = np.abs(moments.sum(axis=1)).max(axis=1)
    if gap is None:
        return flux, remainder, missed, scale, None, None
    return (flux, remainder, missed, scale,
            *_gap_terms(mesh, cells, coefficients, finest, k, gap, lame))


def _gap_terms(mesh, cells, coefficients, sub: SubSimplices, k: int, gap, lame):
    """||C^-1/2 sym(g - tau)||_T^2 and ||skw(g - tau)||_T^2 per element of ``cells``, g - tau
    (degree max(k, 1) on every sub-simplex) squared exactly with GAP_DEGREE[k]."""
    if k not in GAP_DEGREE:
        raise ValueError(f"k={k} has no rule for the stress gap here (allowed: "
                         f"{sorted(GAP_DEGREE)})")
    d = mesh.dim()
    X, W = mapped_rule(sub.corners, get_quadrature(sub.refdom, GAP_DEGREE[k]))
    x, A, det = _mapped(mesh, cells, X)
    tau = np.einsum("nac,nrcsq->ransq", A, sub.values(coefficients, X)) / det[:, None, None]
    values = gap(x, cells, X.reshape(d, -1)) - tau.reshape(d, d, cells.size, -1)
    sym = 0.5 * (values + values.transpose(1, 0, 2, 3))
    energy = compliance_energy(sym.reshape(d * d, *sym.shape[2:]), *lame)
    skew = ((0.5 * (values - values.transpose(1, 0, 2, 3))) ** 2).sum(axis=(0, 1))
    weights = W.ravel()[None] * det[:, None]
    return (energy * weights).sum(axis=1), (skew * weights).sum(axis=1)



def _sub_moments(mesh, cells, body_force, k: int, sub: SubSimplices):
    """int_S r (n, n_sub, d) and int_S |r|^2 (n, n_sub), r = f - Pi_k f, per sub-simplex of
    every element of ``cells``, and int_T |f| (n,), the largest over the rows: one rule of
    degree RULE_DEGREE per sub-simplex, Pi_k f the L2 projection on T with the same rule (so
    the moments sum to zero on T up to round-off)."""
    d = mesh.dim()
    X, W = mapped_rule(sub.corners, get_quadrature(sub.refdom, RULE_DEGREE))
    shape = W.shape                                                      # (n_sub, nq)
    x, _, det = _mapped(mesh, cells, X)
    f = body_force(x)                                                    # (d, n, n_sub nq)
    q = scalar_values(scalar_lagrange(k, d), X.reshape(d, -1))           # (n_dg, n_sub nq)
    w = W.ravel()
    mass = np.einsum("lp,mp,p->lm", q, q, w)
    coefficients = np.linalg.solve(mass, np.einsum("rnp,lp,p->lrn", f, q, w).reshape(
        q.shape[0], -1)).reshape(q.shape[0], d, -1)
    r = f - np.einsum("lrn,lp->rnp", coefficients, q)
    weighted = w.reshape(shape) * det[:, None, None]                     # (n, n_sub, nq)
    moments = (r.reshape(d, -1, *shape) * weighted).sum(axis=-1).transpose(1, 2, 0)
    squares = ((r**2).sum(axis=0).reshape(-1, *shape) * weighted).sum(axis=-1)
    scale = (np.abs(f).reshape(d, -1, *shape) * weighted).sum(axis=(2, 3)).max(axis=0)
    return moments, squares, scale


def _mapped(mesh, cells, X: np.ndarray):
    """The physical points (d, n, m) of the reference points X (d, ...) (m of them) in every
    element of ``cells``, the elements' J (n, d, d) and |det J| (n,)."""
    mapping = mesh.mapping()
    A = mapping.A[:, :, cells]
    x = np.einsum("ijn,jq->inq", A, X.reshape(X.shape[0], -1)) + mapping.b[:, cells, None]
    return x, A.transpose(2, 0, 1), np.abs(mapping.detA[cells])


def _sub_diameters(A: np.ndarray, sub: SubSimplices) -> np.ndarray:
    """h_S (n, n_sub): the longest edge of every sub-simplex mapped by A (n, d, d)."""
    d = A.shape[1]
    pairs = [(i, j) for i in range(d + 1) for j in range(i + 1, d + 1)]
    edges = np.stack([sub.corners[:, j] - sub.corners[:, i] for i, j in pairs], axis=1)
    return np.linalg.norm(np.einsum("nij,sej->nsei", A, edges), axis=-1).max(axis=-1)


def _least_flux(A: np.ndarray, moments: np.ndarray, sub: SubSimplices):
    """||tau||_T^2 (n,) of the least RT_0 flux on the sub-simplices of every element (affine
    map A (n, d, d)), summed over the d rows of ``moments`` (n, n_sub, d), and its inner-face
    coefficients (n, n_inner, d): c = M^-1 B^T S^-1 m, ||tau||^2 = m^T S^-1 m, S = B M^-1 B^T,
    the last sub-simplex's equation dropped (the moments sum to zero on T). M = s M_1 with
    s = tr(J^T J) / |det J| and M_1 the same for every element of one shape, so c needs one
    factorisation per shape (bisected meshes repeat few)."""
    gram = np.einsum("npi,npj->nij", A, A)
    scale = np.trace(gram, axis1=1, axis2=2)
    shape = np.round(gram / scale[:, None, None], 12).reshape(len(A), -1)
    shapes, which = np.unique(shape, axis=0, return_inverse=True)
    mass = np.einsum("npq,pqFG->nFG", shapes.reshape(-1, *gram.shape[1:]), sub.tensors)
    B = sub.incidence[:-1]
    lower = np.linalg.cholesky(mass)
    half = np.linalg.solve(lower, np.broadcast_to(B.T, (len(mass), *B.T.shape)))
    inverse = np.linalg.inv(np.einsum("nfs,nft->nst", half, half))       # S_1^-1
    # M_1^-1 B^T S_1^-1 = L^-T (L^-1 B^T) S_1^-1
    solution = np.linalg.solve(lower.transpose(0, 2, 1), half) @ inverse
    m = moments[:, :-1]
    which = which.ravel()
    coefficients = np.einsum("nfs,nsr->nfr", solution[which], m)
    squares = np.einsum("nsr,nst,ntr->n", m, inverse[which], m)
    return scale / np.abs(np.linalg.det(A)) * squares, coefficients

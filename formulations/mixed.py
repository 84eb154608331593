"""``mixed``: Haslinger's mixed method, the seed paper's (3) (docs/theory.md, section 3).

lambda_H is piecewise constant on a contact mesh T_{C,H} coarser than the trace of T_h. The QP is
min 1/2 u'Ku - F'u s.t. Bu <= G with B_ij = int_{S_i} phi_j . n ds and G_i = int_{S_i} g ds, so
the KKT multiplier of row i is the value of lambda_H on segment S_i.

Contact mesh (h/H <= 1/2 by construction, on uniform and adaptive meshes alike): the segments
are runs of consecutive contact facets, each as short as possible subject to every facet in it
being at most half its length. On a uniform trace that pairs neighbouring facets (H = 2h, as in
the paper); on a graded trace the segments follow the grading. (Maximal dyadic parents of the
facets would not: on graded traces they stay as coarse as the coarsest facet around, and on the
Hertz scene, whose contact zone is smaller than one initial facet, such a multiplier mesh lags
the refinement by a dozen levels.)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import sparse
from skfem import MeshTri

from formulations.base import ContactQP, DiscreteSolution, QPSolution, Residuals
from formulations.contact import contact_trace, gauss_legendre
from formulations.discretisation import Discretisation, discrete_solution
from formulations.elasticity import assemble_elasticity
from formulations.kkt import count_active
from formulations.registry import register_formulation
from scenes import Scene
from scenes.base import is_number

GAP_QUADRATURE_POINTS = 6  # G_i = int g: g is smooth on each facet; 6 Gauss points is plenty


@dataclass(frozen=True, eq=False)
class MixedDetails:
    """The mixed method's own arrays: the multiplier segment of every contact facet."""

    segment_of_facet: np.ndarray


def multiplier_segments(lengths: np.ndarray, h_over_H: float = 0.5) -> np.ndarray:
    """Segment index of every contact facet (facets in order along Gamma_C), see the module
    docstring: greedy runs of consecutive facets, each closed as soon as its longest facet is
    at most ``h_over_H`` times its length (twice for the default 1/2); a short remainder is
    merged backwards until it qualifies. ``h_over_H = 1`` makes every facet a segment.

    A sequential scan over the contact facets only (O(n) with n ~ sqrt(ndofs)); the rule
    depends on the running maximum, which has no closed vectorised form."""
    tol = 1e-12 * float(lengths.sum())
    ends, run_length, run_max = [], 0.0, 0.0
    for k, h in enumerate(lengths):
        run_length, run_max = run_length + h, max(run_max, h)
        if run_length >= run_max / h_over_H - tol:
            ends.append(k + 1)
            run_length, run_max = 0.0, 0.0
    if not ends or ends[-1] != lengths.size:
        ends = ends[:-1] + [lengths.size]  # merge the remainder with the run before it
        while len(ends) > 1:
            tail = lengths[ends[-2]:]
            if tail.sum() >= tail.max() / h_over_H - tol:
                break
            del ends[-2]
    starts = np.zeros(lengths.size, dtype=int)
    starts[np.array(ends[:-1], dtype=int)] = 1
    return np.cumsum(starts)


@register_formulation("mixed", "Haslinger's mixed method: piecewise constant multiplier on a "
                               "coarser contact mesh, h/H <= 1/2 (seed paper, eq. (3))")
def discretise(scene: Scene, mesh: MeshTri, h_over_H: float = 0.5) -> Discretisation:
    """``h_over_H``: the largest allowed ratio of a facet to its multiplier segment. The
    paper's 1/2 (default) keeps the pair uniformly inf-sup stable; 1 (multiplier mesh = trace
    mesh) is not guaranteed to be (a hard case, see ``formulations.diagnostics``)."""
    if not (is_number(h_over_H) and 0.0 < h_over_H <= 1.0):
        raise ValueError(f"h_over_H={h_over_H!r} is not in (0, 1]")
    elasticity = assemble_elasticity(scene, mesh)
    trace = contact_trace(scene, mesh)
    segment = multiplier_segments(trace.length, h_over_H)
    m = int(segment.max()) + 1
    H = np.bincount(segment, weights=trace.length, minlength=m)
    h_over_H = float((trace.length / H[segment]).max())

    # B_ij = int_{S_i} phi_j . n ds: phi_j is linear on a facet, so each end gets h/2 * n
    dofs = elasticity.basis.nodal_dofs
    rows = np.tile(segment, 4)
    cols = np.concatenate([dofs[c, trace.vertices[k]] for k in (0, 1) for c in (0, 1)])
    vals = np.concatenate([0.5 * trace.length * trace.normal[c] for _ in (0, 1) for c in (0, 1)])
    B = sparse.csr_matrix((vals, (rows, cols)), shape=(m, elasticity.basis.N))
    t, w = gauss_legendre(GAP_QUADRATURE_POINTS)
    G = np.bincount(segment, weights=trace.integrate(scene.gap(trace.points(t)), w), minlength=m)

    qp = ContactQP(K=elasticity.K_free, F=elasticity.F[elasticity.free],
                   B=B[:, elasticity.free].tocsr(), G=G, row_scale=H,
                   objective_scale=float(scene.material.young_modulus))
    first = np.flatnonzero(np.diff(np.concatenate([[-1], segment])))
    breaks = np.append(trace.coordinate[0, first], trace.coordinate[1, -1])

    def recover(answer: QPSolution, residuals: Residuals, status: str,
                reason: str) -> DiscreteSolution:
        lam = np.maximum(answer.multipliers, 0.0)
        return discrete_solution(
            "mixed", elasticity, trace, answer, residuals, status, reason, u_free=answer.u,
            pressure=lambda tt: np.repeat(lam[segment][:, None], len(tt), axis=1),
            multiplier_breaks=breaks, active_constraints=count_active(qp, answer.u, lam),
            max_h_over_H=h_over_H, details=MixedDetails(segment_of_facet=segment))

    return Discretisation(formulation="mixed", elasticity=elasticity, trace=trace, qp=qp,
                          recover=recover, row_coordinate=0.5 * (breaks[:-1] + breaks[1:]),
                          multiplier_gram=H**2)  # sum_S H_S ||mu||_{0,S}^2 = sum H_S^2 mu_S^2

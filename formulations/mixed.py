"""``mixed``: Haslinger's mixed method, the seed paper's (3) (DESIGN.md section 3).

lambda_H is piecewise constant on a contact mesh T_{C,H} coarser than the trace of T_h. The QP is
min 1/2 u'Ku - F'u s.t. Bu <= G with B_ij = int_{S_i} phi_j . n ds and G_i = int_{S_i} g ds, so
the KKT multiplier of row i is the value of lambda_H on segment S_i.

Contact mesh (h/H <= 1/2 by construction, on uniform and adaptive meshes alike). Every contact
facet is a dyadic piece of an initial contact facet (scikit-fem's red and red-green-blue
refinements bisect edges). A facet's *parent* is the dyadic interval one level up; the parent of
an initial facet is its pair of initial facets. Dyadic intervals are nested or disjoint, so the
maximal parents partition Gamma_C; these are the multiplier segments, and every facet is at most
half of the segment containing it.
"""

from __future__ import annotations

import numpy as np
from scipy import sparse
from skfem import MeshTri

from formulations.base import ContactQP, DiscreteSolution, QPSolution, Residuals
from formulations.contact import ContactTrace, contact_trace, gauss_legendre
from formulations.discretisation import Discretisation, discrete_solution
from formulations.elasticity import assemble_elasticity
from formulations.kkt import count_active
from formulations.registry import register_formulation
from scenes import Scene

GAP_QUADRATURE_POINTS = 6  # G_i = int g: g is smooth on each facet; 6 Gauss points is plenty


class NotDyadicError(ValueError):
    """The contact trace is not a bisection refinement of the initial mesh's trace."""


def multiplier_segments(trace: ContactTrace, initial: ContactTrace) -> np.ndarray:
    """Segment index of every contact facet (see the module docstring)."""
    breaks = np.append(initial.coordinate[0], initial.coordinate[1, -1])
    n0 = breaks.size - 1
    tol = 1e-9 * (breaks[-1] - breaks[0])
    s0, s1 = trace.coordinate
    root = np.clip(np.searchsorted(breaks, 0.5 * (s0 + s1)) - 1, 0, n0 - 1)
    width = breaks[root + 1] - breaks[root]
    a, b = (s0 - breaks[root]) / width, (s1 - breaks[root]) / width
    level = np.rint(-np.log2(b - a)).astype(int)
    index = np.rint(a * 2.0**level).astype(int)
    if (np.abs(b - a - 2.0**-level) > 1e-8).any() or (np.abs(a - index * 2.0**-level) > 1e-8).any():
        raise NotDyadicError("the mixed formulation needs a contact trace obtained by bisecting "
                             "the initial mesh's contact facets")
    # parent interval: dyadic one level up, or the pair of initial facets for level 0
    parent_width = 2.0 ** (1 - level)
    p0 = breaks[root] + width * (index // 2) * parent_width
    p1 = p0 + width * parent_width
    pair = np.minimum(root // 2, max(n0 // 2 - 1, 0))
    top = level == 0
    p0[top] = breaks[2 * pair[top]]
    p1[top] = breaks[np.where(2 * pair[top] + 2 >= n0 - 1, n0, 2 * pair[top] + 2)]
    covered = np.maximum.accumulate(np.concatenate([[-np.inf], p1[:-1]]))
    starts = p0 >= covered - tol
    return np.cumsum(starts) - 1


@register_formulation("mixed", "Haslinger's mixed method: piecewise constant multiplier on a "
                               "coarser contact mesh, h/H <= 1/2 (seed paper, eq. (3))")
def discretise(scene: Scene, mesh: MeshTri) -> Discretisation:
    elasticity = assemble_elasticity(scene, mesh)
    trace = contact_trace(scene, mesh)
    segment = multiplier_segments(trace, contact_trace(scene, scene.mesh))
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
            max_h_over_H=h_over_H, extra={"multipliers": lam, "segment_of_facet": segment})

    return Discretisation(formulation="mixed", elasticity=elasticity, trace=trace, qp=qp,
                          recover=recover, row_coordinate=0.5 * (breaks[:-1] + breaks[1:]))

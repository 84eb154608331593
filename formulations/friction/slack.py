"""The friction QP shared by the penalty and Nitsche's method (docs/theory.md, 17.2): a
squared positive part per quadrature point for the normal law and a Huber function for the
tangential one, each with one slack.

With normal rows P (a length per point), tangential rows R (a length per point), weights D_q
(a stress per length times the point's share of Gamma_C) and bounds b_q (a force),

    min 1/2 u'Ku - F'u + 1/2 sum_q D_q (q_q^2 + r_q^2) + sum_q b_q |R u - w - r_q|
    s.t. P u - q_q <= g_q,

with q_q and r_q free: min_q {q^2 : q >= x} is (x)_+^2, and min_r (D r^2 / 2 + b |x - r|) is
D times Huber's function of x with threshold b / D, whose derivative is the projection of D x
onto [-b, b]. b_q is w_q s(x_q) (Tresca) or mu times the multiplier of the point's normal row,
which is w_q times the pressure at x_q (Coulomb). In 3D R u - w and r_q are vectors of the
two tangents' components, |.| their length, and the projection is onto the disc of radius b
(a second-order cone per point). The frictional active set solves it
(``formulations.solvers.friction``) and the reference judges it.
"""

from __future__ import annotations

import numpy as np
from scipy import sparse

from formulations.base import ContactQP, FrictionRows
from formulations.cells.evaluation import evaluate_on_trace
from formulations.friction.nodal import interleaved, slide_components


def contact_tangent(trace) -> np.ndarray:
    """t = n turned by +90 degrees on every contact facet (2D): the direction of u_t."""
    return np.array([-trace.normal[1], trace.normal[0]])


def contact_tangents(trace) -> list[np.ndarray]:
    """The tangents of every contact facet: t (2D), or the frame t_1, t_2 of
    ``contact_boundary.tangent_frame`` (3D)."""
    return trace.tangents()


def tangential_rows(elasticity, trace, t: np.ndarray) -> sparse.csr_matrix:
    """u -> u_h . t_k at the points ``t`` of every contact facet, over the free DOFs (in 3D
    both tangents per point, point-major)."""
    at = evaluate_on_trace(elasticity.basis, trace, t)
    nq = t.shape[-1]
    return elasticity.restrict(interleaved([at.matrix(np.repeat(tangent, nq, axis=1))
                                            for tangent in contact_tangents(trace)]))


def shear_vectors(values: np.ndarray, tangents: list[np.ndarray]) -> np.ndarray:
    """sum_k values_k t_k (d, n_facets, nt) from the components ``values`` (n_facets, nt,
    d - 1) along each facet's tangents (``contact_tangents``)."""
    return sum(values[..., k][None] * tangent[:, :, None] for k, tangent in enumerate(tangents))


def slack_friction_qp(scene, K: sparse.spmatrix, F: np.ndarray, P: sparse.spmatrix,
                      R: sparse.spmatrix, gap: np.ndarray, weights: np.ndarray,
                      row_length: np.ndarray, points: np.ndarray,
                      tangents: list[np.ndarray],
                      near_null: np.ndarray | None = None) -> ContactQP:
    """The QP of the module docstring: unknowns u, the normal slacks, the tangential slacks;
    ``row_length`` the points' shares w_q |e| of Gamma_C, ``points`` their positions,
    ``tangents`` the facets' (``contact_tangents``), ``near_null`` the rigid-body modes of
    K (the first unknowns; the slacks' block is diagonal)."""
    law, ns = scene.friction, row_length.size
    block = R.shape[0] // ns  # tangential directions per point: d - 1
    eye, eye_t = sparse.identity(ns, format="csr"), sparse.identity(block * ns, format="csr")
    bound = np.zeros(ns)
    if law.kind == "tresca":
        bound = row_length * np.ravel(law.slip_bound_at(points))
    friction = FrictionRows(T=sparse.hstack([R, sparse.csr_matrix((block * ns, ns)), -eye_t],
                                            format="csr"),
                            bound=bound, coefficient=law.coefficient, block=block,
                            shift=slide_components(law.slide, [
                                np.repeat(tangent, ns // tangent.shape[1], axis=1)
                                for tangent in tangents]))
    return ContactQP(K=sparse.block_diag([K, sparse.diags(weights),
                                          sparse.diags(np.repeat(weights, block))],
                                         format="csr"),
                     F=np.concatenate([F, np.zeros((1 + block) * ns)]),
                     B=sparse.hstack([P, -eye, sparse.csr_matrix((ns, block * ns))],
                                     format="csr"), G=gap,
                     row_scale=np.ones(ns),
                     objective_scale=float(scene.material.young_modulus),
                     near_null=near_null, friction=friction)

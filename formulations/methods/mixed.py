"""``mixed``: Haslinger's mixed method, the seed paper's (3) (docs/theory.md, section 3).

For P1, lambda_H is piecewise constant on a contact mesh T_{C,H} coarser than the trace of T_h.
The QP is min 1/2 u'Ku - F'u s.t. Bu <= G with B_ij = int_{S_i} phi_j . n ds and
G_i = int_{S_i} g ds, so the KKT multiplier of row i is the value of lambda_H on segment S_i.
For P_p (p = 2, 3), lambda_H has degree p - 1 on each segment, written in the Bernstein basis
B_k of the segment, and the rows are int_S B_k phi_j . n ds: the multipliers are the Bernstein
coefficients, so lambda_H >= 0 wherever they are (docs/theory.md, section 9).

Contact mesh (h/H <= 1/2 by construction, on uniform and adaptive meshes alike): the segments
are runs of consecutive contact facets, each as short as possible subject to every facet in it
being at most half its length. On a uniform trace that pairs neighbouring facets (H = 2h, as in
the paper); on a graded trace the segments follow the grading. (Maximal dyadic parents of the
facets would not: on graded traces they stay as coarse as the coarsest facet around, and on the
Hertz scene, whose contact zone is smaller than one initial facet, such a multiplier mesh lags
the refinement by a dozen levels.)

On a quadrilateral hierarchy the segments are the seed's T_CH instead: the Gamma_C edges of the
contact cells' ancestors log2(H/h) levels up (one for h/H = 1/2), from the cell family
(``formulations.cells``; docs/theory.md, section 15.3).

On tetrahedra (``formulations.methods.mixed_surface``, docs/theory.md, section 19.2) lambda_H
is continuous and piecewise linear on the contact surface one level coarser than the trace's
Lagrange lattice (P1: the coarse surface; P2: the trace mesh), or piecewise constant on patches
(the coarse triangles, or vertex stars: the default with friction).
"""

from __future__ import annotations

import functools
from math import comb

import numpy as np
from scipy import sparse
from skfem import MeshTri

from formulations.base import ContactQP, DiscreteSolution, QPSolution, Residuals
from formulations.cells import family_of
from formulations.cells.evaluation import normal_trace_matrix
from formulations.contact import contact_trace
from formulations.contact.reference_facets import gauss_legendre
from formulations.discretisation import Discretisation, discrete_solution
from formulations.elasticity import assemble_elasticity, check_order
from formulations.friction.mixed import mixed_friction_rows, mixed_friction_state
from formulations.kkt import count_active
from formulations.methods.mixed_surface import MixedDetails, discretise_surface
from formulations.registry import register_formulation
from scenes import Scene
from scenes.base import is_integer, is_number

GAP_QUADRATURE_POINTS = 6  # G_i = int g: g is smooth on each facet; 6 Gauss points is plenty


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


def bernstein(degree: int, tau: np.ndarray) -> np.ndarray:
    """The Bernstein polynomials C(q, k) tau^k (1 - tau)^(q - k), k = 0..q, at tau in [0, 1];
    shape (q + 1,) + tau.shape. Non-negative, summing to 1."""
    tau = np.asarray(tau, dtype=float)
    return np.array([comb(degree, k) * tau**k * (1 - tau) ** (degree - k)
                     for k in range(degree + 1)])


def bernstein_gram(degree: int) -> np.ndarray:
    """int_0^1 B_i B_j (the Bernstein mass matrix on [0, 1])."""
    i, j = np.meshgrid(np.arange(degree + 1), np.arange(degree + 1), indexing="ij")
    return np.vectorize(comb)(degree, i) * np.vectorize(comb)(degree, j) / (
        np.vectorize(comb)(2 * degree, i + j) * (2 * degree + 1))


def segment_basis(trace, segment: np.ndarray, breaks: np.ndarray, degree: int,
                  t: np.ndarray) -> np.ndarray:
    """The Bernstein polynomials of each facet's segment (in the segment's contact coordinate,
    ``breaks``: segment end points) at local coordinates t of every facet; shape
    (q + 1, n_facets, len(t))."""
    a, b = breaks[:-1][segment], breaks[1:][segment]
    tau = (trace.coordinates_at(np.asarray(t, dtype=float)) - a[:, None]) / (b - a)[:, None]
    return bernstein(degree, np.clip(tau, 0.0, 1.0))


def segment_weights(trace, segment: np.ndarray, breaks: np.ndarray, degree: int,
                    t: np.ndarray, w: np.ndarray) -> sparse.csr_matrix:
    """W with (W v)_(S, k) = int_S B_k v ds for v given at the points ``t`` (weights ``w``) of
    every contact facet (column f * len(t) + q)."""
    psi = segment_basis(trace, segment, breaks, degree, t)  # (q + 1, n_facets, nq)
    vals = psi * (trace.length[:, None] * w[None, :])[None]
    nf, nq = psi.shape[1:]
    rows = (segment[None, :, None] * (degree + 1) + np.arange(degree + 1)[:, None, None])
    cols = np.arange(nf * nq).reshape(nf, nq)[None]
    m = (int(segment.max()) + 1) * (degree + 1)
    return sparse.csr_matrix((vals.ravel(), (np.broadcast_to(rows, vals.shape).ravel(),
                                             np.broadcast_to(cols, vals.shape).ravel())),
                             shape=(m, nf * nq))


def checked_options(h_over_H: float, order: int, multiplier_degree: int | None):
    """(order, q) after checking the options of ``discretise`` (one-line errors)."""
    if not (is_number(h_over_H) and 0.0 < h_over_H <= 1.0):
        raise ValueError(f"h_over_H={h_over_H!r} is not in (0, 1]")
    order = check_order(order)
    degree = order - 1 if multiplier_degree is None else multiplier_degree
    if not (is_integer(degree) and 0 <= degree <= order):
        raise ValueError(f"multiplier_degree={multiplier_degree!r} is not an integer in "
                         f"[0, order={order}]")
    return order, degree


def no_multiplier_space(scene=None, family=None, **_) -> str | None:
    """Why the mixed method cannot run on ``family``'s cells: no multiplier space is built on
    their contact boundary (``MULTIPLIER_SPACES``), or None."""
    if family is None or family.contact_boundary in MULTIPLIER_SPACES:
        return None
    return (f"the mixed method has no multiplier space on {family.contact_boundary} (it has "
            f"one on {', '.join(MULTIPLIER_SPACES)})")


@register_formulation("mixed", "Haslinger's mixed method: multiplier of degree p - 1 "
                               "(piecewise constant for P1) on a coarser contact mesh, "
                               "h/H <= 1/2 (seed paper, eq. (3)); in 3D on the contact "
                               "surface one level coarser, piecewise constant (P1) or "
                               "continuous piecewise linear (P2); Tresca or "
                               "Coulomb friction with a tangential multiplier in the same "
                               "space (2D and 3D)", no_multiplier_space, friction=(2, 3))
def discretise(scene: Scene, mesh: MeshTri, h_over_H: float | None = None, order: int = 1,
               multiplier_degree: int | None = None,
               multiplier_mesh: str | None = None) -> Discretisation:
    """``h_over_H``: the largest allowed ratio of a facet to its multiplier segment. The
    paper's 1/2 (the default in 2D) keeps the pair uniformly inf-sup stable; 1 (multiplier
    mesh = trace mesh) is not guaranteed to be (a hard case, see ``formulations.diagnostics``).
    ``multiplier_degree``: the polynomial degree q of lambda_H on each segment (default
    p - 1, docs/theory.md, section 9). On a quadrilateral hierarchy h_over_H = 2^-k takes the
    edges k levels up (module docstring). On tetrahedra (``mixed_surface``) h_over_H = 1/2
    means the surface one level coarser, 1 the contact triangles, q is 0 or 1 (default 1:
    P1 on the coarse surface, P2 on the trace mesh), and ``multiplier_mesh = "star"`` takes
    the vertex-star patches instead (q = 0, the default with friction)."""
    why = no_multiplier_space(family=family_of(mesh))
    if why is not None:
        raise ValueError(why)
    return MULTIPLIER_SPACES[family_of(mesh).contact_boundary](scene, mesh, h_over_H, order,
                                                               multiplier_degree,
                                                               multiplier_mesh)


def discretise_segments(scene: Scene, mesh, h_over_H: float | None, order: int,
                        multiplier_degree: int | None,
                        multiplier_mesh: str | None = None) -> Discretisation:
    """The mixed method on a 2D Gamma_C: lambda_H of degree q on segments of edges (the
    coarser contact mesh; ``multiplier_mesh`` has no other value here)."""
    h_over_H = 0.5 if h_over_H is None else h_over_H
    if multiplier_mesh not in (None, "coarse"):
        raise ValueError(f"multiplier_mesh={multiplier_mesh!r} is not allowed on a 2D contact "
                         f"boundary: coarse")
    order, degree = checked_options(h_over_H, order, multiplier_degree)
    elasticity = assemble_elasticity(scene, mesh, order)
    trace = contact_trace(scene, mesh)
    segment = family_of(mesh).multiplier_groups(mesh, trace, h_over_H)
    if segment is None:  # no hierarchy: runs of facets (module docstring)
        segment = multiplier_segments(trace.length, h_over_H)
    H = np.bincount(segment, weights=trace.length)
    h_over_H = float((trace.length / H[segment]).max())

    first = np.flatnonzero(np.diff(np.concatenate([[-1], segment])))
    breaks = np.append(trace.coordinate[0, first], trace.coordinate[1, -1])
    # B_(S,k) j = int_S B_k phi_j . n ds: degree q + p on a facet, exact with p + 1 points
    t, w = gauss_legendre(order + 1)
    B = segment_weights(trace, segment, breaks, degree, t, w) @ normal_trace_matrix(
        elasticity.basis, trace, t)
    friction = mixed_friction_rows(scene, elasticity, trace, functools.partial(
        segment_weights, trace, segment, breaks, degree), order, GAP_QUADRATURE_POINTS)
    t, w = gauss_legendre(GAP_QUADRATURE_POINTS)
    G = segment_weights(trace, segment, breaks, degree, t, w) @ np.ravel(
        scene.gap(trace.points(t)))
    qp = ContactQP(K=elasticity.K_free, F=elasticity.F_free,
                   B=elasticity.restrict(B), G=G, row_scale=np.repeat(H, degree + 1),
                   objective_scale=float(scene.material.young_modulus),
                   near_null=elasticity.rigid_modes, friction=friction)
    # each coefficient sits at its Greville point k / q of the segment (the middle for q = 0)
    greville = np.array([0.5]) if degree == 0 else np.linspace(0.0, 1.0, degree + 1)
    row_coordinate = (breaks[:-1, None] + np.diff(breaks)[:, None] * greville).ravel()

    def recover(answer: QPSolution, residuals: Residuals, status: str,
                reason: str) -> DiscreteSolution:
        lam = np.maximum(answer.multipliers, 0.0)
        return discrete_solution(
            "mixed", elasticity, trace, answer, residuals, status, reason, u_free=answer.u,
            pressure=lambda tt: np.einsum("kft,fk->ft",
                                          segment_basis(trace, segment, breaks, degree, tt),
                                          lam.reshape(-1, degree + 1)[segment]),
            multiplier_breaks=breaks, active_constraints=count_active(qp, answer.u, lam),
            max_h_over_H=h_over_H, details=MixedDetails(segment_of_facet=segment),
            friction=None if friction is None else mixed_friction_state(
                friction, answer.u, lam, answer.tangential, row_coordinate,
                lambda tt: segment_basis(trace, segment, breaks, degree, tt), segment))

    # Gram matrix of sum_S H_S ||mu||_{0,S}^2: H_S^2 times the Bernstein mass matrix per segment
    gram = sparse.kron(sparse.diags(H**2), bernstein_gram(degree)).toarray() if degree else H**2
    return Discretisation(formulation="mixed", elasticity=elasticity, trace=trace, qp=qp,
                          recover=recover, row_coordinate=row_coordinate,
                          multiplier_gram=gram)


# the multiplier space of the mixed method on each contact boundary (formulations.contact)
MULTIPLIER_SPACES = {"edges": discretise_segments, "triangles": discretise_surface}

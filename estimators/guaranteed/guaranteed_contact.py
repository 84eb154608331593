"""The auxiliary contact traction and the contact terms of the guaranteed bound
(docs/theory.md, sections 13.1 and 13.3).

lambda* is the formulation's pressure lambda_h plus a continuous piecewise linear correction
delta on Gamma_C chosen so that u_h balances the hat functions psi_a e_i of every vertex off
Gamma_D for the auxiliary problem with traction -lambda* n (exactly zero for the mixed method up
to its solver's tolerance; the quadrature and nodal reactions of penalty and vi). With an
extension d of w = (g - u_hn)_- (``estimators.guaranteed.contact_extension``), ``contact_bound``
gives the contact terms D, ||lambda*_-|| and B.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import sparse
from scipy.sparse.linalg import spsolve

from estimators.guaranteed.contact_extension import Extension, discrete_gap, vertex_normals
from estimators.guaranteed.equilibration import BoundaryData, boundary_balance, boundary_fluxes
from estimators.guaranteed.strip_extension import StripExtension
from formulations.contact.reference_facets import gauss_legendre

QUADRATURE = 10     # Gauss points per contact facet for the kinked integrands


@dataclass(frozen=True, eq=False)
class ContactTraction:
    """lambda*(t) = lambda(t) + delta_start (1 - t) + delta_end t on each contact facet, lambda
    the formulation's pressure projected onto P_k per facet (``projected_pressure``)."""

    pressure: object            # the formulation's lambda_h(t), (n_f, len(t))
    delta: np.ndarray           # (2, n_f): the correction at the start and end of each facet

    def __call__(self, t: np.ndarray) -> np.ndarray:
        return self.pressure(t) + self.delta[0][:, None] * (1 - t) + self.delta[1][:, None] * t


PROJECTION_POINTS = 24  # Gauss points per facet for projecting a kinked lambda_h onto P_k


@dataclass(frozen=True, eq=False)
class FacetPolynomial:
    """A function on the contact facets that is a polynomial of degree k on each: Legendre
    coefficients (n_f, k + 1) on [0, 1]; called like ``DiscreteSolution.pressure``."""

    coefficients: np.ndarray

    def __call__(self, t: np.ndarray) -> np.ndarray:
        shifted = np.polynomial.legendre.legvander(2 * np.asarray(t) - 1,
                                                   self.coefficients.shape[1] - 1)
        return self.coefficients @ shifted.T


def projected_pressure(pressure, k: int) -> FacetPolynomial:
    """The L2 projection of ``pressure(t)`` onto P_k on each facet (docs/theory.md, 13.3): as a
    part of lambda* it keeps every moment against the hat functions (P_1 within P_k), and the
    auxiliary problem's contact traction becomes one the RT_k stress meets exactly, so it adds
    no oscillation; a kinked penalty or Nitsche pressure otherwise does."""
    t, w = gauss_legendre(PROJECTION_POINTS)
    legendre = np.polynomial.legendre.legvander(2 * t - 1, k)        # (nq, k + 1)
    norms = 2 * np.arange(k + 1) + 1                                  # 1 / ||P_j||^2 on [0, 1]
    return FacetPolynomial((pressure(t) * w) @ legendre * norms)


def facet_parameter(trace, x: np.ndarray) -> np.ndarray:
    """Local coordinate t in [0, 1] of points x (2, n_f, nq) on the contact facets."""
    a = trace.mesh.p[:, trace.vertices[0]][:, :, None]
    b = trace.mesh.p[:, trace.vertices[1]][:, :, None]
    return ((x - a) * (b - a)).sum(axis=0) / ((b - a) ** 2).sum(axis=0)


def traction_at(trace, pressure, x: np.ndarray, direction: np.ndarray | None = None
                ) -> np.ndarray:
    """-pressure n at points x (2, n_f, nq) of the contact facets, with ``pressure(t)`` as
    ``DiscreteSolution.pressure`` (the same local points on every facet, in any order); with
    a ``direction`` (2, n_f) instead of -n: pressure times it (a shear traction along t)."""
    t = facet_parameter(trace, x)
    common = np.unique(np.round(t, 12))
    values = pressure(common)
    index = np.abs(t[:, :, None] - common[None, None, :]).argmin(axis=-1)
    vector = -trace.normal if direction is None else direction
    return np.take_along_axis(values, index, axis=1)[None] * vector[:, :, None]


def traction_balance(interior, trace, pressure, direction: np.ndarray | None = None
                     ) -> np.ndarray:
    """int psi_a t over Gamma_C per vertex, (n_vertices, 2), for the traction t of
    ``pressure`` as in ``traction_at`` (-pressure n, or pressure times ``direction``)."""
    part = BoundaryData(trace.facets, lambda x: traction_at(trace, pressure, x, direction))
    return boundary_balance(interior.total.shape[0], boundary_fluxes(interior, [part]))


def contact_mass(trace, weight: np.ndarray | None = None) -> sparse.csr_matrix:
    """The mass matrix of continuous P1 on Gamma_C (segments or triangles) over all mesh
    vertices: |e| (1 + delta_ij) / (m (m + 1)) on a facet e of m vertices; with a ``weight``
    (n_f,) per facet, each facet's part divided by it."""
    m, n_v, size = trace.vertices.shape[0], trace.mesh.p.shape[1], trace.measure
    if weight is not None:
        size = size / weight
    pairs = [(i, j) for i in range(m) for j in range(m)]
    rows = np.concatenate([trace.vertices[i] for i, _ in pairs])
    cols = np.concatenate([trace.vertices[j] for _, j in pairs])
    vals = np.concatenate([size / (m * (m + 1) / (1 + (i == j))) for i, j in pairs])
    return sparse.coo_matrix((vals, (rows, cols)), shape=(n_v, n_v)).tocsr()


def balanced_traction(trace, pressure, defect: np.ndarray, clamped: np.ndarray,
                      orientation: float = -1.0, directions: np.ndarray | None = None,
                      weight: np.ndarray | None = None):
    """lambda* from lambda_h and the per-vertex imbalance ``defect`` (n_vertices, 2) of the
    auxiliary problem with lambda_h: M delta = -defect . nu on the contact vertices off Gamma_D
    (M the P1 mass matrix of Gamma_C), and the imbalance left in tangential directions. For a
    traction ``orientation`` x value x ``directions`` (vertex vectors, (2, n_vertices)) in
    general: M delta = orientation defect . directions (a shear: +1 and the vertex tangents).
    With a ``weight`` omega (n_f,) per facet, delta is the linear function per facet of least
    sum_e omega_e ||delta||_e^2 with these moments: mu / omega_e on facet e, M_omega mu = the
    same right-hand side, M_omega the mass matrix with facet e's part divided by omega_e
    (docs/theory.md, 13.3; omega = 1 is the continuous P1 delta)."""
    start, end = trace.vertices
    n_v = trace.mesh.p.shape[1]
    M = contact_mass(trace, weight)
    nu = vertex_normals(trace) if directions is None else directions
    on = np.unique(np.concatenate([start, end]))
    on = on[~clamped[on]]
    delta = np.zeros(n_v)
    if on.size:
        rhs = orientation * (defect[on] * nu[:, on].T).sum(axis=1)
        delta[on] = np.atleast_1d(spsolve(M[on][:, on].tocsc(), rhs))
    scale = 1.0 if weight is None else 1.0 / weight
    return ContactTraction(pressure=pressure,
                           delta=np.array([delta[start], delta[end]]) * scale)


@dataclass(frozen=True)
class ContactBound:
    extension: float        # D = ||d||, d . n <= w on Gamma_C
    negative: float         # ||lambda*_-||_{0,Gamma_C}
    complementarity: float  # (lambda*_+, g - u_hn - d . n)_{Gamma_C} >= 0
    energy: np.ndarray      # a(d, d) per element
    negative_squares: np.ndarray  # ||lambda*_-||^2 over each element's contact facets
    negative_part: np.ndarray     # lambda*_- (n_facets, QUADRATURE) at the Gauss points
    slack: np.ndarray       # |(lambda*_+, g - u_hn - d . n)| over each element's contact facets
    field: Extension | StripExtension  # d itself


@dataclass(frozen=True)
class ContactBounds:
    """The contact terms of lambda* for every extension d (docs/theory.md, 13.3): with the
    one-layer fields (``marking``: they steer marking) and with the same fields relaxed off
    Gamma_C (``sharp``: same trace, so the same N and B, a smaller D; they enter eta)."""

    marking: tuple[ContactBound, ...]
    sharp: tuple[ContactBound, ...]


def contact_bound(scene, solution, traction: ContactTraction, d: Extension | StripExtension,
                  energy: np.ndarray) -> ContactBound:
    """D, ||lambda*_-|| and B of lambda* = ``traction`` with the extension ``d`` (13.1);
    ``energy`` is a(d, d) per element (``d.energy``; it does not depend on the traction, so
    the caller computes it once for all tractions)."""
    trace = solution.trace
    t, w = gauss_legendre(QUADRATURE)
    d_n = d.along(trace, trace.normal, t)
    lam = traction(t)
    slack = trace.integrate(np.maximum(lam, 0.0) * (discrete_gap(scene, solution, t) - d_n), w)
    return bound_of(trace, lam, trace.integrate(np.minimum(lam, 0.0) ** 2, w), slack, d, energy)


def bound_of(trace, lam: np.ndarray, negative: np.ndarray, slack: np.ndarray, d,
             energy: np.ndarray) -> ContactBound:
    """The ``ContactBound`` of lambda* at the quadrature points (``lam``, (n_f, nq)), with
    ||lambda*_-||^2 (``negative``) and (lambda*_+, g - u_hn - d . n) (``slack``) per contact
    facet, the extension ``d`` and a(d, d) per element."""
    n_el = trace.mesh.t.shape[1]
    return ContactBound(extension=float(np.sqrt(energy.sum())),
                        negative=float(np.sqrt(negative.sum())),
                        complementarity=float(max(slack.sum(), 0.0)), energy=energy,
                        negative_squares=np.bincount(trace.element, negative, n_el),
                        negative_part=np.minimum(lam, 0.0),
                        slack=np.bincount(trace.element, np.abs(slack), n_el), field=d)

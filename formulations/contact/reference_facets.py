"""Reference facets (docs/theory.md, sections 1 and 14): quadrature and Lagrange bases on the
unit interval (a 2D body's edges) and the unit triangle (a tetrahedral body's faces), the
facts every contact boundary and estimator builds on."""

from __future__ import annotations

import numpy as np
from skfem import ElementTriP1, ElementTriP2, ElementTriP3
from skfem.quadrature import get_quadrature_tri


def gauss_legendre(n: int) -> tuple[np.ndarray, np.ndarray]:
    """n-point Gauss-Legendre rule on [0, 1]: points t and weights w (sum w = 1)."""
    x, w = np.polynomial.legendre.leggauss(n)
    return 0.5 * (x + 1.0), 0.5 * w


def lagrange_nodes(order: int) -> np.ndarray:
    """The equispaced nodes k / p (k = 0..p) on [0, 1] of the trace of a P_p Lagrange element
    on one facet."""
    return np.linspace(0.0, 1.0, order + 1)


def lagrange_basis(nodes: np.ndarray, t: np.ndarray) -> np.ndarray:
    """The 1D Lagrange polynomials on ``nodes`` at t; shape (len(nodes), len(t))."""
    t = np.asarray(t, dtype=float)
    out = np.ones((nodes.size, t.size))
    for k in range(nodes.size):
        for j in range(nodes.size):
            if j != k:
                out[k] *= (t - nodes[j]) / (nodes[k] - nodes[j])
    return out


def lagrange_basis_1d(order: int, t: np.ndarray) -> np.ndarray:
    """The 1D Lagrange polynomials of degree p on the nodes ``lagrange_nodes(p)`` at t;
    shape (p + 1, len(t))."""
    return lagrange_basis(lagrange_nodes(order), t)


def facet_coordinates(coordinate: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Contact coordinates at local coordinates t in [0, 1] of facets whose end points are
    ``coordinate`` (2, n); shape (n, len(t)) (affine along a facet of a straight Gamma_C)."""
    s0, s1 = coordinate
    return s0[:, None] + (s1 - s0)[:, None] * np.asarray(t)[None, :]


def newton_cotes(order: int) -> np.ndarray:
    """int_0^1 L_k dt for the 1D Lagrange polynomials L_k on the equispaced nodes k / p (the
    lumped boundary mass per unit facet length: 1/2, 1/2 for P1; 1/6, 2/3, 1/6 for P2 --
    Simpson; 1/8, 3/8, 3/8, 1/8 for P3); all positive for p <= 3."""
    t, w = gauss_legendre(order + 1)
    return lagrange_basis_1d(order, t) @ w


def nodal_interpolant(values: np.ndarray, t: np.ndarray) -> np.ndarray:
    """The piecewise linear interpolant along each facet of its p + 1 nodal ``values``
    (n_facets, p + 1) at local coordinates t: (n_facets, len(t))."""
    pieces = values.shape[1] - 1
    x = np.clip(np.asarray(t, dtype=float), 0.0, 1.0) * pieces
    k = np.minimum(np.floor(x).astype(int), pieces - 1)
    return values[:, k] + (values[:, k + 1] - values[:, k]) * (x - k)[None, :]


# the reference triangle's vertices as local coordinates (2, 3)
TRIANGLE_VERTICES = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
# where a traction is sampled on each triangle: its corners, edge midpoints and centroid
TRIANGLE_SAMPLES = np.array([[0, 1, 0, 0.5, 0.5, 0, 1 / 3], [0, 0, 1, 0, 0.5, 0.5, 1 / 3]])
# the sub-triangles of a P2 triangle between its nodes (ElementTriP2's order)
P2_CHILDREN = np.array([[0, 3, 5], [3, 1, 4], [5, 4, 2], [3, 4, 5]])


# scikit-fem's triangle rules of these degrees have a negative weight: the next one is taken (a
# penalty weight D_q must be positive)
NEGATIVE_WEIGHT_DEGREES = (3, 7)


def triangle_rule(degree: int) -> tuple[np.ndarray, np.ndarray]:
    """A rule exact to ``degree`` with positive weights on the reference triangle: points t
    (2, nq) and weights w (nq,) with sum w = 1 (scikit-fem's rules, whose weights sum to the
    area 1/2)."""
    degree = max(int(degree), 1)
    t, w = get_quadrature_tri(degree + (degree in NEGATIVE_WEIGHT_DEGREES))
    return t, 2.0 * w


def triangle_lagrange(order: int):
    """The Lagrange nodes (2, k) of P_order on the reference triangle (scikit-fem's
    ``ElementTriP*`` DOF order: vertices, edges, interior) and ``basis(t)`` (k, nq), the
    Lagrange polynomials at local coordinates t (2, nq)."""
    element = {1: ElementTriP1, 2: ElementTriP2, 3: ElementTriP3}[int(order)]()
    nodes = np.asarray(element.doflocs, dtype=float).T

    def basis(t: np.ndarray) -> np.ndarray:
        return np.array([element.lbasis(np.asarray(t, dtype=float), k)[0]
                         for k in range(nodes.shape[1])])

    return nodes, basis


def barycentric(corners: np.ndarray, s: np.ndarray) -> np.ndarray:
    """Local coordinates (2, m) of points s (2, m) in 2D triangles with corners (2, 3, m)."""
    a, b, c = corners[:, 0], corners[:, 1], corners[:, 2]
    e1, e2, r = b - a, c - a, s - a
    det = e1[0] * e2[1] - e1[1] * e2[0]
    return np.array([(r[0] * e2[1] - r[1] * e2[0]) / det, (e1[0] * r[1] - e1[1] * r[0]) / det])

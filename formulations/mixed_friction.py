"""Friction in the mixed method (docs/theory.md, 17.2): a tangential multiplier lambda_t,H in
the normal one's space (degree q on each segment S of the contact mesh, Bernstein
coefficients), as in Haslinger and Hlavacek's mixed formulation of given friction.

The tangential rows are T_(S,k) u = int_S B_k u_h . t ds (t = n turned by +90 degrees), the
bound on each coefficient |lambda_t,(S,k)| <= b_(S,k): Tresca's
b = int_S B_k s ds / int_S B_k ds (for q = 0 the mean of s on S), Coulomb's mu lambda_n,(S,k).
By the Bernstein basis' convex hull property the Coulomb bound on the coefficients gives
|lambda_t,H| <= mu lambda_n,H everywhere on S; Tresca's holds where s is its own mean. The
multipliers are tractions: sigma_t,H = -lambda_t,H.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy import sparse

from formulations.base import FrictionRows, FrictionState
from formulations.contact import gauss_legendre
from formulations.evaluation import evaluate_on_trace
from formulations.friction_state import friction_state


def tangential_rows(elasticity, trace, weights: sparse.csr_matrix,
                    t: np.ndarray) -> sparse.csr_matrix:
    """T = W P_t on the free DOFs: P_t u = u_h . t at the points ``t`` of every facet, W the
    segments' Bernstein weights at those points (``mixed.segment_weights``)."""
    tangent = np.array([-trace.normal[1], trace.normal[0]])
    at_points = evaluate_on_trace(elasticity.basis, trace, t).matrix(
        np.repeat(tangent, t.shape[-1], axis=1))
    return elasticity.restrict(weights @ at_points)


def mixed_friction_rows(scene, elasticity, trace, weights_at, order: int,
                        points: int) -> FrictionRows | None:
    """The ``FrictionRows`` of ``scene``'s law on the coefficients (None without friction):
    ``weights_at(t, w)`` integrates values at the points t of every facet against each B_k
    (``mixed.segment_weights``); the rows with order + 1 Gauss points per facet (exact, as the
    normal rows), the bounds with ``points``."""
    law = scene.friction
    if not law.active:
        return None
    t, w = gauss_legendre(order + 1)
    T = tangential_rows(elasticity, trace, weights_at(t, w), t)
    t, w = gauss_legendre(points)
    weights = weights_at(t, w)
    mass = np.asarray(weights @ np.ones(weights.shape[1])).ravel()  # int_S B_k ds
    bound = np.zeros(mass.size)
    if law.kind == "tresca":
        bound = (weights @ np.ravel(law.slip_bound_at(trace.points(t)))) / mass
    shift = law.slide * mass if law.slide else None  # int_S B_k (obstacle's slide) ds
    return FrictionRows(T=T, bound=bound, coefficient=law.coefficient, shift=shift)


def mixed_friction_state(friction: FrictionRows, u_free: np.ndarray, normal: np.ndarray,
                         tangential: np.ndarray | None, coordinate: np.ndarray,
                         basis_at: Callable[[np.ndarray], np.ndarray],
                         segment: np.ndarray) -> FrictionState:
    """The coefficients' states and sigma_t,H = -sum_k lambda_t,(S,k) B_k along the facets
    (``basis_at(t)``: the Bernstein values of each facet's segment, (q + 1, n_facets, nt))."""
    if tangential is None:  # a failed solve: NaN, never a silent zero
        tangential = np.full(friction.T.shape[0], np.nan)
    degree = basis_at(np.array([0.5])).shape[0] - 1
    coefficients = tangential.reshape(-1, degree + 1)

    def traction(t):
        return -np.einsum("kft,fk->ft", basis_at(t), coefficients[segment])

    return friction_state(friction, u_free, normal, tangential, np.ones(tangential.size),
                          coordinate, traction)

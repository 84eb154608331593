"""Friction in the mixed method (docs/theory.md, 17.2): a tangential multiplier lambda_t,H in
the normal one's space (degree q on each segment S of the contact mesh, Bernstein
coefficients), as in Haslinger and Hlavacek's mixed formulation of given friction.

The tangential rows are T_(S,k) u = int_S B_k u_h . t ds (t = n turned by +90 degrees), the
bound on each coefficient |lambda_t,(S,k)| <= b_(S,k): Tresca's
b = int_S B_k s ds / int_S B_k ds (for q = 0 the mean of s on S), Coulomb's mu lambda_n,(S,k).
By the Bernstein basis' convex hull property the Coulomb bound on the coefficients gives
|lambda_t,H| <= mu lambda_n,H everywhere on S; Tresca's holds where s is its own mean. The
multipliers are tractions: sigma_t,H = -lambda_t,H. On a 3D contact surface lambda_t,H is a
constant vector per patch of the normal multiplier's (two tangential rows per patch), bounded by
a disc.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy import sparse

from formulations.base import FrictionRows, FrictionState
from formulations.cells.evaluation import drop_roundoff, evaluate_on_trace
from formulations.contact.boundary import tangent_frame
from formulations.contact.reference_facets import gauss_legendre
from formulations.friction.nodal import interleaved, slide_components
from formulations.friction.state import friction_state


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


def surface_friction_rows(scene, elasticity, surface, patch: np.ndarray, weights, t: np.ndarray,
                          bound_points: tuple[np.ndarray, np.ndarray]):
    """(FrictionRows, frame) of ``scene``'s law on the patches of a 3D contact surface (None,
    None without friction): lambda_t,P a constant vector per patch in its tangent plane (the
    frame of the patch's area-weighted normal), rows T_(P,k) u = int_P u_h . t_k ds
    (``weights`` integrates values at the points ``t`` of every facet over each patch), and
    |lambda_t,P| <= the mean of s on P (Tresca, by the rule ``bound_points``) or
    mu lambda_n,P (Coulomb); an obstacle sliding by w = slide e_x shifts the rows by
    int_P w . t_k ds."""
    law = scene.friction
    if not law.active:
        return None, None
    area = np.bincount(patch, weights=surface.measure)
    normal = np.array([np.bincount(patch, weights=surface.measure * n) for n in surface.normal])
    frame = tangent_frame(normal / np.linalg.norm(normal, axis=0))
    at = evaluate_on_trace(elasticity.basis, surface, t)
    nq = t.shape[-1]
    T = interleaved([drop_roundoff(elasticity.restrict(
        weights @ at.matrix(np.repeat(tangent[:, patch], nq, axis=1)))) for tangent in frame])
    bound = np.zeros(area.size)
    if law.kind == "tresca":
        tb, wb = bound_points
        s = np.asarray(law.slip_bound_at(surface.points(tb))).reshape(patch.size, -1)
        bound = np.bincount(patch, weights=(s * wb[None, :]).sum(axis=1) * surface.measure) / area
    shift = slide_components(law.slide, frame)  # int_P w . t_k ds
    return FrictionRows(T=T, bound=bound, coefficient=law.coefficient, block=2,
                        shift=None if shift is None else shift * np.repeat(area, 2)), frame


def surface_friction_state(friction: FrictionRows, u_free: np.ndarray, normal: np.ndarray,
                           tangential: np.ndarray | None, coordinate: np.ndarray,
                           patch: np.ndarray, frame: list[np.ndarray]) -> FrictionState:
    """The patches' states and sigma_t,H = -lambda_t,P (a vector, constant on each patch)."""
    if tangential is None:  # a failed solve: NaN, never a silent zero
        tangential = np.full(friction.T.shape[0], np.nan)
    pairs = tangential.reshape(-1, 2)
    vectors = -(pairs[:, 0] * frame[0] + pairs[:, 1] * frame[1])  # (3, n_patches)

    def traction(tt):
        return np.repeat(vectors[:, patch][:, :, None], np.shape(tt)[-1], axis=2)

    return friction_state(friction, u_free, normal, tangential, np.ones(pairs.shape[0]),
                          coordinate, traction)

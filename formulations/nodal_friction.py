"""Friction on the nodes of Gamma_C for the nodal VI (docs/theory.md, 17.2).

At every constraint node x_i (normal n_i, lumped weight w_i) the tangential row is
T_i u = t_i . u_h(x_i) with t_i = (-n_2, n_1) (n_i turned by +90 degrees), and the friction
functional is j_h(u) = sum_i w_i s(x_i) |T_i u| (Tresca: the lumped quadrature of
int_{Gamma_C} s |u_t| ds), or the same with w_i s(x_i) replaced by mu times the normal reaction
(Coulomb). The tangential reaction lambda_t,i is a force; the shear traction at the node is
sigma_t = -lambda_t,i / w_i (friction opposes the slip).
"""

from __future__ import annotations

import numpy as np

from formulations.base import FrictionRows, FrictionState
from formulations.friction_state import friction_state


def tangents(normal: np.ndarray) -> np.ndarray:
    """t_i = (-n_2, n_1): the unit normals turned by +90 degrees (2D; the cell family
    refuses friction on tetrahedra, where the bound is a disc)."""
    if normal.shape[0] != 2:
        raise ValueError(f"tangential rows need 2D normals, not {normal.shape[0]}D ones")
    return np.array([-normal[1], normal[0]])


def friction_rows(scene, nodes, T) -> FrictionRows | None:
    """The ``FrictionRows`` of ``scene``'s law on ``nodes`` with tangential rows ``T`` (free
    DOFs), or None without friction."""
    law = scene.friction
    if not law.active:
        return None
    bound = (nodes.weight * law.slip_bound_at(nodes.points) if law.kind == "tresca"
             else np.zeros(nodes.weight.size))
    shift = np.full(nodes.weight.size, law.slide) if law.slide else None
    return FrictionRows(T=T, bound=bound, coefficient=law.coefficient, shift=shift)


def facet_interpolant(values: np.ndarray, t: np.ndarray) -> np.ndarray:
    """The piecewise linear interpolant along each 2D facet of its p + 1 nodal ``values``
    (n_facets, p + 1) at local coordinates t: (n_facets, len(t))."""
    pieces = values.shape[1] - 1
    x = np.clip(np.asarray(t, dtype=float), 0.0, 1.0) * pieces
    k = np.minimum(np.floor(x).astype(int), pieces - 1)
    return values[:, k] + (values[:, k + 1] - values[:, k]) * (x - k)[None, :]


def nodal_friction(friction: FrictionRows, u_free: np.ndarray, reactions: np.ndarray,
                   tangential: np.ndarray, nodes, coordinate: np.ndarray) -> FrictionState:
    """The node states and tractions from the returned arrays (``friction_state``)."""
    shear = -tangential / nodes.weight
    return friction_state(friction, u_free, reactions, tangential, 1.0 / nodes.weight,
                          coordinate, lambda t: facet_interpolant(shear[nodes.facet_rows], t))

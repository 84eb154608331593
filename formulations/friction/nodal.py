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
from scipy import sparse

from formulations.base import FrictionRows, FrictionState
from formulations.contact.reference_facets import nodal_interpolant, triangle_lagrange
from formulations.friction.state import friction_state


def interleaved(rows: list[sparse.csr_matrix]) -> sparse.csr_matrix:
    """The rows of each matrix in turn per node: (T_1)_0, (T_2)_0, (T_1)_1, ... (node-major,
    as ``FrictionRows`` has them)."""
    m = rows[0].shape[0]
    order = np.arange(len(rows) * m).reshape(len(rows), m).T.ravel()
    return sparse.vstack(rows, format="csr")[order]


def slide_components(slide: float, frame: list[np.ndarray]) -> np.ndarray | None:
    """The obstacle's slide w along each row's tangent, point-major (None if it does not
    slide): in 2D ``slide`` along t, in 3D w = slide e_x, so w . t_k = slide (t_k)_x."""
    if not slide:
        return None
    if len(frame) == 1:
        return np.full(frame[0].shape[1], float(slide))
    return float(slide) * np.stack([tangent[0] for tangent in frame], axis=1).ravel()


def friction_rows(scene, nodes, T, frame: list[np.ndarray]) -> FrictionRows | None:
    """The ``FrictionRows`` of ``scene``'s law on ``nodes`` with tangential rows ``T`` (free
    DOFs, one per tangent of ``frame`` and node), or None without friction."""
    law = scene.friction
    if not law.active:
        return None
    bound = (nodes.weight * law.slip_bound_at(nodes.points) if law.kind == "tresca"
             else np.zeros(nodes.weight.size))
    return FrictionRows(T=T, bound=bound, coefficient=law.coefficient,
                        shift=slide_components(law.slide, frame), block=len(frame))


def nodal_friction(friction: FrictionRows, u_free: np.ndarray, reactions: np.ndarray,
                   tangential: np.ndarray, nodes, coordinate: np.ndarray,
                   frame: list[np.ndarray]) -> FrictionState:
    """The node states and tractions from the returned arrays (``friction_state``); in 3D
    ``traction(t)`` is the shear vector sum_k sigma_k t_k, (3, n_facets, nq), interpolated
    per component from the nodes (``frame`` the nodes' tangents)."""
    shear = -tangential / np.repeat(nodes.weight, friction.block)
    if friction.block == 1:
        def traction(t):
            return nodal_interpolant(shear[nodes.facet_rows], t)
    else:
        vectors = sum(shear.reshape(-1, 2)[:, k] * frame[k] for k in range(2))  # (3, m)
        basis = triangle_lagrange(nodes.facet_rows.shape[1] // 3)[1]

        def traction(t):
            at = basis(np.asarray(t, dtype=float))
            return np.stack([vectors[c][nodes.facet_rows] @ at for c in range(3)])
    return friction_state(friction, u_free, reactions, tangential, 1.0 / nodes.weight,
                          coordinate, traction)

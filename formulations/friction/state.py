"""The friction law's answer at a formulation's friction points, computed from the returned
arrays (docs/theory.md, 17.2): what a solution says about sticking, slipping and separation."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from formulations.base import FrictionRows, FrictionState

# a point is in contact where its normal multiplier exceeds this fraction of the largest one,
# and slips where |lambda_t| is within it (times the largest bound) of its bound: the exact
# solver leaves round-off, the interior-point reference ~1e-9 relative
STATE_FRACTION = 1e-6


def friction_state(friction: FrictionRows, u_free: np.ndarray, normal: np.ndarray,
                   tangential: np.ndarray, to_stress: np.ndarray, coordinate: np.ndarray,
                   traction: Callable[[np.ndarray], np.ndarray]) -> FrictionState:
    """The states and tractions of the friction points (rows of ``friction.T``) from the
    normal and tangential multipliers; ``to_stress`` turns a multiplier into a traction (1 /
    w_i for vi's forces, 1 for the mixed method's coefficients; one per point), ``traction(t)``
    gives sigma_t,h on the contact facets. A point in contact with a zero bound slides freely:
    it slips. In 3D a point has two tangential entries (``friction.block``) and |.| is their
    norm."""
    bound = friction.bounds(normal)
    size = friction.node_norms(tangential)
    contact = normal > STATE_FRACTION * max(normal.max(initial=0.0), 0.0)
    slipping = size >= bound - STATE_FRACTION * bound.max(initial=0.0)
    state = np.where(~contact, "separated", np.where(slipping, "slip", "stick"))
    return FrictionState(coordinate=coordinate, tangential_reactions=tangential,
                         shear=-tangential * np.repeat(to_stress, friction.block),
                         slip=friction.slip(u_free), bound=bound,
                         state=state, traction=traction, bound_traction=bound * to_stress)


def traction_size(values: np.ndarray) -> np.ndarray:
    """|sigma_t| from ``FrictionState.traction(t)``: the absolute value of the 2D traction
    (n_facets, nt), the length of the 3D vector (3, n_facets, nt)."""
    values = np.asarray(values)
    return np.linalg.norm(values.reshape((-1,) + values.shape[-2:]), axis=0)

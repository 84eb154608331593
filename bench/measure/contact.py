"""Contact quantities of a discrete solution: the contact zone, its distance to a true zone,
and the penetration of the obstacle."""

from __future__ import annotations

import numpy as np

from formulations import DiscreteSolution
from formulations.contact import lagrange_nodes
from formulations.kkt import ACTIVE_FRACTION


def contact_zone(solution: DiscreteSolution) -> tuple[float, float]:
    """End points (contact coordinates) of the union of contact facets where lambda_h > 0,
    i.e. above ACTIVE_FRACTION x max lambda_h: an interior-point solution leaves multipliers
    of ~1e-9 relative on every facet, which are not contact."""
    values = solution.pressure(np.array([0.25, 0.5, 0.75]))
    pressed = (values > ACTIVE_FRACTION * values.max(initial=0.0)).any(axis=1)
    if not pressed.any():
        return float("nan"), float("nan")
    s0, s1 = solution.trace.coordinate
    return float(s0[pressed].min()), float(s1[pressed].max())


def zone_error(zone: tuple[float, float], true_zone: tuple[float, float]) -> float:
    """The larger distance between the end points of two contact zones."""
    return float(max(abs(zone[0] - true_zone[0]), abs(zone[1] - true_zone[1])))


def penetration(scene, solution: DiscreteSolution) -> float:
    """max over the Lagrange nodes of Gamma_C of (u_h . n - g)^+ (a length)."""
    trace, nodes = solution.trace, lagrange_nodes(solution.elasticity.order)
    u_n = solution.normal_displacement(nodes)
    gap = np.asarray(scene.gap(trace.points(nodes)))
    return float(np.maximum(u_n - gap, 0.0).max(initial=0.0))

"""Contact quantities of a discrete solution: the contact zone, its distance to a true zone,
and the penetration of the obstacle."""

from __future__ import annotations

import numpy as np

from formulations import DiscreteSolution


def contact_zone(solution: DiscreteSolution) -> tuple[float, float]:
    """The contact zone's ends (contact coordinates) where lambda_h > 0 (the contact
    boundary's ``zone``: the pressed facets' extent along a 2D Gamma_C, the disc of the
    pressed area on a 3D one)."""
    return solution.trace.zone(solution.pressure)


def zone_error(zone: tuple[float, float], true_zone: tuple[float, float]) -> float:
    """The larger distance between the end points of two contact zones."""
    return float(max(abs(zone[0] - true_zone[0]), abs(zone[1] - true_zone[1])))


def penetration(scene, solution: DiscreteSolution) -> float:
    """max over the Lagrange nodes of Gamma_C of (u_h . n - g)^+ (a length)."""
    trace = solution.trace
    nodes = trace.lagrange_points(solution.elasticity.order)
    u_n = solution.normal_displacement(nodes)
    gap = np.asarray(scene.gap(trace.points(nodes)))
    return float(np.maximum(u_n - gap, 0.0).max(initial=0.0))

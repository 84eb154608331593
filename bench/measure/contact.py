"""Contact quantities of a discrete solution: the contact zone, its distance to a true zone,
and the penetration of the obstacle."""

from __future__ import annotations

import numpy as np

from formulations import DiscreteSolution
from formulations.contact import lagrange_nodes
from formulations.contact_surface import triangle_lagrange
from formulations.kkt import ACTIVE_FRACTION

DISC_DEGREE = 10  # 25 points per contact triangle for the area of the contact zone


def contact_zone(solution: DiscreteSolution) -> tuple[float, float]:
    """End points (contact coordinates) of the union of contact facets where lambda_h > 0,
    i.e. above ACTIVE_FRACTION x max lambda_h: an interior-point solution leaves multipliers
    of ~1e-9 relative on every facet, which are not contact."""
    if solution.trace.dim == 3:
        return contact_disc(solution)
    values = solution.pressure(np.array([0.25, 0.5, 0.75]))
    pressed = (values > ACTIVE_FRACTION * values.max(initial=0.0)).any(axis=1)
    if not pressed.any():
        return float("nan"), float("nan")
    s0, s1 = solution.trace.coordinate
    return float(s0[pressed].min()), float(s1[pressed].max())


def contact_disc(solution: DiscreteSolution) -> tuple[float, float]:
    """A 3D contact zone as (c - r, c + r): r the radius of the disc of the same area as the
    part of Gamma_C where lambda_h > ACTIVE_FRACTION x max lambda_h (by quadrature), c the
    first contact coordinate of its centroid (docs/theory.md, section 14.2)."""
    trace = solution.trace
    t, w = trace.rule(DISC_DEGREE)
    values = solution.pressure(t)
    pressed = values > ACTIVE_FRACTION * values.max(initial=0.0)
    area = trace.integrate(pressed.astype(float), w).sum()
    if area <= 0:
        return float("nan"), float("nan")
    centre = trace.integrate(pressed * trace.coordinates_at(t)[0], w).sum() / area
    radius = float(np.sqrt(area / np.pi))
    return float(centre - radius), float(centre + radius)


def zone_error(zone: tuple[float, float], true_zone: tuple[float, float]) -> float:
    """The larger distance between the end points of two contact zones."""
    return float(max(abs(zone[0] - true_zone[0]), abs(zone[1] - true_zone[1])))


def penetration(scene, solution: DiscreteSolution) -> float:
    """max over the Lagrange nodes of Gamma_C of (u_h . n - g)^+ (a length)."""
    trace = solution.trace
    nodes = (lagrange_nodes(solution.elasticity.order) if trace.dim == 2
             else triangle_lagrange(solution.elasticity.order)[0])
    u_n = solution.normal_displacement(nodes)
    gap = np.asarray(scene.gap(trace.points(nodes)))
    return float(np.maximum(u_n - gap, 0.0).max(initial=0.0))

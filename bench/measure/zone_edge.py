"""The contact zone's edge by the square-root law (docs/theory.md, section 14.2).

Where a smooth obstacle leaves a smooth body, the Signorini pressure vanishes like the square
root of the distance to the zone's edge (Hertz's p0 (1 - r^2 / a^2)^(1/2) is one case), so
lambda^2 is linear across the edge. The support of a discrete pressure ends at a node: a
piecewise linear lambda_h is positive on the whole facet beyond its last pressed node, and the
zone {lambda_h > 0} overshoots by up to a facet. Here lambda_h^2 is taken at the pressure's
Lagrange nodes, as a piecewise linear function on the facets cut into sub-simplices at those
nodes; at every unpressed node next to the zone it is replaced by its linear extrapolation from
the pressed neighbours (the mean gradient of lambda_h^2 on the fully pressed sub-simplices at
each), and the zone is where that function is positive, measured exactly per sub-simplex.
Where no gradient is available (an isolated pressed node) the unpressed node keeps 0.

The edge lies inside the support of lambda_h, so the zone reported is cut back, never grown:
in 2D the intersection with the support (``contact.contact_zone``), in 3D the smaller of the
two equivalent radii. The law fits a continuous pressure given by its nodal values (vi's); a
pressure defined pointwise (the penalty's, Nitsche's) or piecewise constant on patches
(the 3D mixed method's) has its edge inside a facet already, and there the support is the
better measure (docs/theory.md, section 14.2, measured).
"""

from __future__ import annotations

import numpy as np

from bench.measure.contact import contact_zone
from formulations import DiscreteSolution
from formulations.kkt import ACTIVE_FRACTION

# P2 triangles cut at their edge midpoints (scikit-fem's order: vertices, then 01, 12, 02)
P2_CHILDREN = np.array([[0, 3, 5], [3, 1, 4], [5, 4, 2], [3, 4, 5]])


def square_root_zone(solution: DiscreteSolution) -> tuple[float, float]:
    """End points of the contact zone (in 3D (c - r, c + r), r the radius of the disc of its
    area, c its centroid's first coordinate), with its edge placed by the square-root law
    (module docstring). NaN, NaN without contact."""
    support = contact_zone(solution)
    nodes, simplices, squared, pressed = _nodal_squares(solution)
    if not pressed.any() or not np.isfinite(squared).all() or np.isnan(support).any():
        return float("nan"), float("nan")
    extended = _extrapolated(nodes, simplices, squared, pressed)
    values = extended[simplices]                      # (n_sub, m + 1)
    corners = nodes[:, simplices]                     # (m, n_sub, m + 1)
    if nodes.shape[0] == 1:
        start, end = _interval_ends(corners[0], values)
        return max(start, support[0]), min(end, support[1])
    fraction = _positive_fraction(values)
    area = 0.5 * np.abs(np.linalg.det((corners[:, :, 1:] - corners[:, :, :1]).transpose(1, 2, 0)))
    zone = (fraction * area).sum()
    if zone <= 0:
        return float("nan"), float("nan")
    centre = (fraction * area * corners[0].mean(axis=1)).sum() / zone
    radius = min(float(np.sqrt(zone / np.pi)), 0.5 * (support[1] - support[0]))
    return float(centre - radius), float(centre + radius)


def _nodal_squares(solution):
    """Contact coordinates (m, N) of the pressure's Lagrange nodes (shared between facets),
    the sub-simplices (n_sub, m + 1) between them, lambda_h^2 there (the least over the
    facets that hold a node: lambda_h may jump between facets, and a node on the edge of a
    piecewise constant lambda_h is not pressed) and which nodes are pressed."""
    trace, order = solution.trace, max(solution.elasticity.order, 1)
    t, local = trace.lattice(order)
    values = solution.pressure(t)                                    # (n, nq)
    flat = trace.row_coordinates(t).reshape(-1, values.size)         # (1 or 2, n nq)
    scale = np.abs(flat).max() + 1.0
    _, first, index = np.unique(np.round(flat / scale, 11), axis=1, return_index=True,
                                return_inverse=True)
    index = index.ravel()
    least = np.full(first.size, np.inf)
    np.minimum.at(least, index, np.nan_to_num(values.ravel(), nan=np.inf))
    nq = t.shape[-1]
    simplices = (index.reshape(-1, nq)[:, local]).reshape(-1, local.shape[1])
    pressed = least > ACTIVE_FRACTION * max(least.max(initial=0.0), 0.0)
    return flat[:, first], simplices, np.where(pressed, least, 0.0) ** 2, pressed


def _extrapolated(nodes, simplices, squared, pressed) -> np.ndarray:
    """lambda_h^2 at the nodes, with every unpressed node next to a pressed one given the mean
    of its pressed neighbours' linear extrapolations, capped at 0."""
    m = nodes.shape[0]
    full = pressed[simplices].all(axis=1)
    grads = _gradients(nodes[:, simplices[full]], squared[simplices[full]])   # (m, n_full)
    at = simplices[full].ravel()
    hits = np.bincount(at, minlength=squared.size)
    mean_grad = np.array([np.bincount(at, np.repeat(g, m + 1), squared.size) for g in grads])
    mean_grad = mean_grad / np.maximum(hits, 1)
    # every ordered pair (i pressed with a gradient, j unpressed) in one sub-simplex
    i, j = (simplices[:, [a for a in range(m + 1) for b in range(m + 1) if a != b]].ravel(),
            simplices[:, [b for a in range(m + 1) for b in range(m + 1) if a != b]].ravel())
    keep = pressed[i] & ~pressed[j] & (hits[i] > 0)
    i, j = i[keep], j[keep]
    guess = squared[i] + (mean_grad[:, i] * (nodes[:, j] - nodes[:, i])).sum(axis=0)
    total = np.bincount(j, guess, squared.size)
    n = np.bincount(j, minlength=squared.size)
    out = squared.copy()
    reached = n > 0
    out[reached] = np.minimum(total[reached] / n[reached], 0.0)
    return out


def _gradients(corners: np.ndarray, values: np.ndarray) -> np.ndarray:
    """The constant gradient (m, n) of the linear interpolant of ``values`` (n, m + 1) on
    simplices with ``corners`` (m, n, m + 1): E' g = d with E the edges from the first corner
    and d the value differences along them, in any dimension m."""
    edges = (corners[:, :, 1:] - corners[:, :, :1]).transpose(1, 2, 0)   # (n, m, m): edge, x
    rise = values[:, 1:] - values[:, :1]                                 # (n, m)
    return np.linalg.solve(edges, rise[..., None])[..., 0].T


def _interval_ends(corners: np.ndarray, values: np.ndarray) -> tuple[float, float]:
    """The smallest and largest coordinate where a piecewise linear function (``values`` at
    the ends ``corners`` of every interval, both (n, 2)) is positive."""
    a, b = values[:, 0], values[:, 1]
    xa, xb = corners[:, 0], corners[:, 1]
    positive = (a > 0) | (b > 0)
    if not positive.any():
        return float("nan"), float("nan")
    with np.errstate(divide="ignore", invalid="ignore"):
        cross = xa + a / (a - b) * (xb - xa)           # the zero of the linear function
    lo = np.where(a > 0, xa, cross)
    hi = np.where(b > 0, xb, cross)
    ends = np.concatenate([lo[positive], hi[positive]])
    return float(np.nanmin(ends)), float(np.nanmax(ends))


def _positive_fraction(values: np.ndarray) -> np.ndarray:
    """The fraction of each triangle where the linear function with vertex ``values`` (n, 3)
    is positive (exact: the corner a level line cuts off is a similar triangle)."""
    v = np.sort(values, axis=1)
    above = (v > 0).sum(axis=1)
    out = (above == 3).astype(float)
    with np.errstate(divide="ignore", invalid="ignore"):
        one = v[:, 2] ** 2 / ((v[:, 2] - v[:, 0]) * (v[:, 2] - v[:, 1]))   # v0, v1 <= 0 < v2
        two = 1 - v[:, 0] ** 2 / ((v[:, 1] - v[:, 0]) * (v[:, 2] - v[:, 0]))  # v0 <= 0 < v1
    out = np.where(above == 1, np.nan_to_num(one, nan=1.0), out)
    out = np.where(above == 2, np.nan_to_num(two, nan=1.0), out)
    return np.clip(out, 0.0, 1.0)

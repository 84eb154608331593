"""Contact quantities of a discrete solution: the contact zone, its distance to a true zone,
and the penetration of the obstacle, with the verdict whether the discrete constraint saw the
contact at all (docs/theory.md, section 19.1)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from formulations import DiscreteSolution

UNRESOLVED_SHARE = 0.1  # a discrete constraint that lets the body undo more than a tenth of
# the obstacle's approach has not seen the contact (the Hertz scenes' lost contacts undo all of
# it; a resolved mixed or vi solution undoes a few per cent between its nodes, measured)
SAMPLE_DEGREE = 4  # the interior sample points: a rule exact to degree 4 on every facet, so the
# maximum of u_h . n - g between the Lagrange nodes (a convex gap) is seen too
STATUS_UNRESOLVED = "contact unresolved"
# the statuses of a level with an answer: its numbers are those of the discrete problem,
# whether or not its constraint saw the contact
SOLVED_STATUSES = ("ok", STATUS_UNRESOLVED)


@dataclass(frozen=True)
class ContactResolution:
    """How far the discrete solution goes through the obstacle: ``penetration`` = the largest
    (u_h . n - g)^+ on Gamma_C (a length), ``approach`` = the largest -g (how far the
    obstacle is pushed into the undeformed body; 0 when the loads make the contact),
    ``nodal_penetration`` = the same at the Lagrange nodes only (what a nodal constraint
    controls), ``penetration_share`` = penetration / approach (with no approach: / max
    |u_h . n|), and ``unresolved``: why the discrete constraint did not see the contact, or ""."""

    penetration: float
    nodal_penetration: float
    approach: float
    penetration_share: float
    unresolved: str

    def columns(self) -> dict:
        return dict(penetration=self.penetration, nodal_penetration=self.nodal_penetration,
                    approach=self.approach, penetration_share=self.penetration_share)


def contact_zone(solution: DiscreteSolution) -> tuple[float, float]:
    """The contact zone's ends (contact coordinates) where lambda_h > 0 (the contact
    boundary's ``zone``: the pressed facets' extent along a 2D Gamma_C, the disc of the
    pressed area on a 3D one)."""
    return solution.trace.zone(solution.pressure)


def zone_error(zone: tuple[float, float], true_zone: tuple[float, float]) -> float:
    """The larger distance between the end points of two contact zones."""
    return float(max(abs(zone[0] - true_zone[0]), abs(zone[1] - true_zone[1])))


def zone_jaccard(zone: tuple[float, float], true_zone: tuple[float, float]) -> float:
    """Jaccard's distance 1 - |Z_h n Z| / |Z_h u Z| of two contact zones taken as intervals
    of the contact coordinate (their extent along the first one in 3D); a missing zone (NaN
    ends) is empty: 1 against a zone, 0 against none."""
    def length(z):
        return float(z[1] - z[0]) if z[0] == z[0] and z[1] == z[1] else 0.0

    a, b = length(zone), length(true_zone)
    both = (max(0.0, min(zone[1], true_zone[1]) - max(zone[0], true_zone[0]))
            if a > 0 and b > 0 else 0.0)
    union = a + b - both
    return 1.0 - both / union if union > 0 else 0.0


def sample_points(trace, order: int) -> np.ndarray:
    """The Lagrange nodes of degree ``order`` and the points of a degree-``SAMPLE_DEGREE``
    rule on every facet (local coordinates)."""
    return np.concatenate([trace.lagrange_points(order), trace.rule(SAMPLE_DEGREE)[0]],
                          axis=-1)


def normal_gap(scene, solution: DiscreteSolution) -> tuple[np.ndarray, np.ndarray]:
    """u_h . n and g at ``sample_points`` of every contact facet."""
    trace = solution.trace
    t = sample_points(trace, solution.elasticity.order)
    return solution.normal_displacement(t), np.asarray(scene.gap(trace.points(t)), float)


def penetration(scene, solution: DiscreteSolution, nodal: bool = False) -> float:
    """max over the sample points of Gamma_C (``nodal``: its Lagrange nodes only) of
    (u_h . n - g)^+ (a length)."""
    resolution = contact_resolution(scene, solution)
    return resolution.nodal_penetration if nodal else resolution.penetration


def contact_resolution(scene, solution: DiscreteSolution) -> ContactResolution:
    """``ContactResolution`` of a solved level: unresolved when the penetration is more than
    ``UNRESOLVED_SHARE`` of the approach, or when the obstacle is pushed in (a negative gap)
    and no constraint is active."""
    u_n, gap = normal_gap(scene, solution)
    excess = np.maximum(u_n - gap, 0.0)
    depth = float(excess.max(initial=0.0))
    nodes = solution.trace.lagrange_points(solution.elasticity.order).shape[-1]
    nodal = float(excess[:, :nodes].max(initial=0.0))
    approach = float(np.maximum(-gap, 0.0).max(initial=0.0))
    scale = approach if approach > 0 else float(np.abs(u_n).max(initial=0.0))
    share = depth / scale if scale > 0 else 0.0
    why = ""
    if approach > 0 and solution.active_constraints == 0:
        why = (f"no constraint is active although the obstacle is pushed {approach:.3g} into "
               f"Gamma_C")
    elif share > UNRESOLVED_SHARE:
        why = (f"penetration {depth:.3g} undoes {share:.0%} of the approach (more than "
               f"{UNRESOLVED_SHARE:.0%})" if approach > 0 else
               f"penetration {depth:.3g} is {share:.0%} of the normal displacement (more "
               f"than {UNRESOLVED_SHARE:.0%})")
    return ContactResolution(depth, nodal, approach, share, why)

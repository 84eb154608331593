"""``contact-zone``: the contact zone's size, the extent of {lambda_h > 0} along the first
contact coordinate (its length in 2D, its diameter in 3D; docs/theory.md, 20.1). The
distance of the computed zone to the true one (Jaccard's) is the result column
``zone_jaccard`` of every row with a truth. No dual problem: the zone's size is no linear or
differentiable function of (u, lambda) (it moves by the pressure's square-root decay at the
zone's end), so the goal estimators skip it."""

from __future__ import annotations

from estimators.quantities.base import Quantity, register_quantity


def size(zone: tuple[float, float]) -> float:
    return float(zone[1] - zone[0]) if zone[0] == zone[0] else 0.0  # NaN: no zone


@register_quantity("contact-zone", "the contact zone's size (length in 2D, diameter in 3D)")
def contact_zone(scene) -> Quantity:
    exact = None if scene.exact is None else size(scene.exact.contact_zone)
    return Quantity(name="contact-zone",
                    evaluate=lambda sol: size(sol.trace.zone(sol.pressure)), exact=exact,
                    from_reference=lambda ref: size(ref.zone), unit="length",
                    why_no_dual="the zone's size is no differentiable function of "
                                "(u, lambda): no dual problem")

"""``contact-force``: the total contact force F = (lambda, 1)_{Gamma_C} (docs/theory.md, 20.1;
a force per unit thickness in 2D). Its dual solution is the body's response to a unit normal
displacement of the contact set."""

from __future__ import annotations

import numpy as np

from estimators.quantities.base import (
    Quantity,
    exact_pressure_integral,
    register_quantity,
    weighted_pressure,
)


def ones(x: np.ndarray) -> np.ndarray:
    """omega = 1 at points or coordinates x ((...,) or (k, ...))."""
    x = np.asarray(x, dtype=float)
    return np.ones(x.shape[1:] if x.ndim > 1 else x.shape)


@register_quantity("contact-force", "the total contact force (lambda, 1) on Gamma_C")
def contact_force(scene) -> Quantity:
    return Quantity(name="contact-force", evaluate=lambda sol: weighted_pressure(sol, ones),
                    exact=exact_pressure_integral(scene, ones),
                    from_reference=lambda reference: float(reference.contact_force),
                    weight=ones, unit="force", energy_interval=True)

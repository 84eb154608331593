"""``mean-pressure``: the mean contact pressure over the middle part of Gamma_C
(docs/theory.md, 20.1): (lambda, omega) / (1, omega) with omega a trapezoid in the contact
coordinate, 1 on the middle eighth of Gamma_C's extent (each way from its centre), falling
linearly to 0 over a further sixteenth. A continuous weight: the dual problem's normal
displacement omega must lie in H^1/2 (an indicator of the part would not)."""

from __future__ import annotations

import numpy as np

from estimators.quantities.base import (
    Quantity,
    contact_box,
    pressure_quantity,
    register_quantity,
)

PLATEAU, RAMP = 1 / 16, 1 / 32  # half-width of the plateau, width of the ramps (of the extent)


def trapezoid(box: np.ndarray):
    """omega(s) over contact coordinates s ((...) in 2D, (k, ...) in 3D) and (1, omega)."""
    centre, extent = box.mean(axis=1), box[:, 1] - box[:, 0]
    plateau, ramp = PLATEAU * extent, RAMP * extent

    def omega(s: np.ndarray) -> np.ndarray:
        s = np.asarray(s, dtype=float).reshape((centre.size, -1) if centre.size > 1 else (1, -1))
        r = np.abs(s - centre[:, None])
        return np.prod(np.clip((plateau[:, None] + ramp[:, None] - r) / ramp[:, None], 0, 1),
                       axis=0)

    return omega, float(np.prod(2 * plateau + ramp))


@register_quantity("mean-pressure", "the mean pressure over the middle part of Gamma_C "
                                    "(a continuous trapezoid weight)")
def mean_pressure(scene) -> Quantity:
    omega, area = trapezoid(contact_box(scene))
    return pressure_quantity("mean-pressure", scene, lambda s: omega(s) / area)

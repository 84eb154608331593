"""``peak-pressure``: the pressure at the centre of Gamma_C, where the scenes with a
closed-form pressure have their peak (Hertz's p0, free-boundary's P0), averaged with a smooth
bump omega = (1 - r^2)^2 of radius 1/64 of Gamma_C's extent (docs/theory.md, 20.1): a point
value of lambda is no functional the dual problem can take (lambda is only in H^-1/2), the
bump's mean is; it differs from the peak by O(r^2 / b^2) (0.3 % for hertz's b ~ 0.1)."""

from __future__ import annotations

import numpy as np

from estimators.quantities.base import (
    Quantity,
    contact_box,
    pressure_quantity,
    register_quantity,
)

RADIUS = 1 / 64  # of Gamma_C's extent


def bump(box: np.ndarray):
    """omega(s) / (1, omega) centred on the box (k, 2)."""
    centre = box.mean(axis=1)
    radius = RADIUS * float((box[:, 1] - box[:, 0]).max())
    k = centre.size
    norm = 16 / 15 * radius if k == 1 else np.pi * radius**2 / 3

    def omega(s: np.ndarray) -> np.ndarray:
        s = np.asarray(s, dtype=float).reshape((k, -1))
        r2 = ((s - centre[:, None]) ** 2).sum(axis=0) / radius**2
        return np.clip(1 - r2, 0, None) ** 2 / norm

    return omega


def predicts_peak(scene=None, **_) -> str | None:
    if scene is not None and scene.exact is None and scene.predict_contact is None:
        return f"scene {scene.name!r} predicts no peak (no closed-form pressure)"
    return None


@register_quantity("peak-pressure", "the pressure at the centre of Gamma_C (a smooth bump's "
                                    "mean), where the closed forms have their peak",
                   applies=predicts_peak)
def peak_pressure(scene) -> Quantity:
    return pressure_quantity("peak-pressure", scene, bump(contact_box(scene)))

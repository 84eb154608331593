"""Friction laws as scene data (docs/theory.md, section 17).

A scene carries one ``FrictionLaw``: ``none`` (frictionless, every scene's default),
``tresca`` (given friction: |sigma_t| <= s on Gamma_C with a slip bound s(x) >= 0 given as a
function, sigma_t = 0 wherever the body does not slip only bounded by s) or ``coulomb``
(|sigma_t| <= mu |sigma_n|: the slip bound is the coefficient times the unknown pressure).
Where |sigma_t| < bound the point sticks (u_t = 0); where it slips, sigma_t = -bound u_t / |u_t|
(friction opposes the slip).

Scenes take the law from three parameters, so that options and sweeps work as for every other
parameter (``paper:friction=coulomb:mu=0.1|0.3``): ``friction`` (the law's name), ``mu`` (the
Coulomb coefficient) and ``slip_bound`` (a constant Tresca bound s, a stress). A scene may also
let the obstacle slide along t by a constant ``slide`` (a length; Cattaneo-Mindlin's tangential
loading): the slip is then u_t - slide. In 3D it slides along x: the slip is u_t - slide e_x.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from scenes.checks import PointFunction, SceneError, is_number

LAWS = ("none", "tresca", "coulomb")


@dataclass(frozen=True, eq=False)
class FrictionLaw:
    """``kind`` one of ``LAWS``; ``coefficient`` the Coulomb mu (0 unless coulomb);
    ``slip_bound`` the Tresca s(x) (None unless tresca)."""

    kind: str = "none"
    coefficient: float = 0.0
    slip_bound: PointFunction | None = None
    # the obstacle's own displacement along t (a length): the slip is u_t - slide
    slide: float = 0.0

    def __post_init__(self):
        if self.kind not in LAWS:
            raise SceneError(f"friction={self.kind!r} is not one of {', '.join(LAWS)}")
        if (self.kind == "tresca") != (self.slip_bound is not None):
            raise SceneError(f"friction={self.kind!r}: a slip bound is given exactly for "
                             "'tresca'")

    def slip_bound_at(self, x: np.ndarray) -> np.ndarray:
        """Tresca's s at points x (d, ...): SceneError if it is negative or not finite."""
        bound = np.asarray(self.slip_bound(x), dtype=float)
        if np.any(bound < 0) or not np.all(np.isfinite(bound)):
            raise SceneError("slip_bound is negative or not finite on Gamma_C (it must be a "
                             "finite function >= 0)")
        return bound

    def slide_vector(self, dim: int) -> np.ndarray:
        """The obstacle's slide w as a vector in 3D (slide e_x; 2D slides along t)."""
        return np.eye(dim)[0] * self.slide

    @property
    def active(self) -> bool:
        """Whether there is friction at all."""
        return self.kind != "none"

    @property
    def label(self) -> str:
        """How a result row names the law: ``none``, ``tresca``, ``coulomb(mu=0.3)``."""
        return f"coulomb(mu={self.coefficient:g})" if self.kind == "coulomb" else self.kind


NO_FRICTION = FrictionLaw()


MU_MAX = 100.0  # beyond it a Coulomb coefficient only costs accuracy (docs/friction.md)


def friction_law(friction: str = "none", mu: float = 0.0, slip_bound: float = 0.0,
                 tresca_bound: PointFunction | None = None, slide: float = 0.0) -> FrictionLaw:
    """The law from a scene's parameters: ``tresca`` takes the constant ``slip_bound`` (a
    stress, > 0) unless the scene gives its own bound function ``tresca_bound``; ``coulomb``
    takes ``mu`` (> 0). A parameter that the law does not use must keep its default, so that a
    sweep cannot silently vary nothing."""
    if friction not in LAWS:
        raise SceneError(f"friction={friction!r} is not one of {', '.join(LAWS)}")
    for name, value in (("mu", mu), ("slip_bound", slip_bound)):
        if not (is_number(value) and np.isfinite(value) and value >= 0):
            raise SceneError(f"{name}={value!r} is not a finite number >= 0")
    if friction != "coulomb" and mu != 0:
        raise SceneError(f"mu={mu!r} needs friction='coulomb' (friction={friction!r})")
    if friction != "tresca" and slip_bound != 0:
        raise SceneError(f"slip_bound={slip_bound!r} needs friction='tresca' "
                         f"(friction={friction!r})")
    if not (is_number(slide) and np.isfinite(slide)):
        raise SceneError(f"slide={slide!r} is not a finite number")
    if friction == "none" and slide != 0:
        raise SceneError(f"slide={slide!r} needs a friction law (friction='none': a "
                         "frictionless obstacle slides without effect)")
    if friction == "coulomb":
        if not 0 < mu <= MU_MAX:
            raise SceneError(f"mu={mu!r} is not in (0, {MU_MAX:g}] (friction='coulomb'): "
                             "measured friction coefficients lie below about 2, and a larger "
                             "one describes no contact and only costs accuracy")
        return FrictionLaw("coulomb", coefficient=float(mu), slide=float(slide))
    if friction == "tresca":
        if tresca_bound is None:
            if slip_bound <= 0:
                raise SceneError(f"slip_bound={slip_bound!r} is not > 0 (friction='tresca')")
            s = float(slip_bound)
            tresca_bound = lambda x: np.full(np.shape(x)[1:], s)  # noqa: E731
        return FrictionLaw("tresca", slip_bound=tresca_bound, slide=float(slide))
    return NO_FRICTION

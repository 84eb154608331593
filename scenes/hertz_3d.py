"""``hertz-3d``: Hertz's contact of a sphere, as Hertz modelled it (docs/theory.md, 14.3).

Hertz's theory (K. L. Johnson, Contact Mechanics, 1985, section 4.2) treats the body as an
elastic half-space pressed by a rigid sphere of radius R, i.e. the paraboloid gap
g(x, y) = (x^2 + y^2) / (2 R) - delta. This scene discretises exactly that: a block
(-W, W)^2 x (-D, 0) clamped on top, pushed up along its bottom face by the paraboloid with
approach delta, traction-free sides. At the contact force P, with E* = E / (1 - nu^2),

    a = (3 P R / (4 E*))^(1/3),   p0 = 3 P / (2 pi a^2),   p(r) = p0 sqrt(1 - r^2 / a^2),

valid while a << D, W. The defaults give a ~ 0.14 (R = 1, delta = 0.02) against D = W = 2; the
half-space assumption's own cost is measured in docs/three-d.md.

With Coulomb friction (``friction="coulomb"``, ``mu``) and the paraboloid sliding along x by
``slide`` after pressing, Mindlin's partial slip (Johnson, section 7.2) leaves a stick disc
r < c = a (1 - Q / (mu P))^(1/3) and the shear traction along x
q(r) = mu p0 (sqrt(1 - r^2/a^2) - (c/a) sqrt(1 - r^2/c^2)), compared at the computed P and Q;
like the 2D theory it neglects the normal-tangential coupling (exact for nu -> 1/2).
"""

from __future__ import annotations

import functools

import numpy as np

from scenes.base import (
    ContactPrediction,
    Material,
    Scene,
    SceneError,
    is_integer,
)
from scenes.budget import tensor_mesh
from scenes.friction import friction_law
from scenes.hertz import partial_slip
from scenes.registry import register_scene

_TOL = 1e-10


def hertz_sphere(young_modulus: float, poisson_ratio: float, radius: float,
                 contact_force: float) -> ContactPrediction:
    """Hertz's pressure p0 sqrt(1 - (r/a)^2) at the force ``contact_force`` (``half_width``
    is the contact radius a)."""
    if not contact_force > 0:  # no contact (a constraint that missed it): nothing to predict
        return ContactPrediction(0.0, 0.0, label="no contact force")
    e_star = young_modulus / (1 - poisson_ratio**2)
    a = float(np.cbrt(3 * contact_force * radius / (4 * e_star)))
    p0 = float(3 * contact_force / (2 * np.pi * a**2))
    return ContactPrediction(a, p0, label=f"Hertz, a = {a:.4g}, p0 = {p0:.4g}")


def mindlin(mu: float, slide: float):
    """(P, Q) -> Mindlin's partial slip under Hertz's sphere: the stick radius
    c = a (1 - |Q| / (mu P))^(1/3), the shear traction along the obstacle's slide."""
    return partial_slip(hertz_sphere, 1.0 / 3.0, "Mindlin", mu, slide)


@register_scene("hertz-3d", "Hertz contact of a sphere: a block pressed by a rigid paraboloid "
                            "of radius R (half-space model); closed-form radius and peak pressure",
                tags=("exact", "hertz", "3d"), dim=3)
def hertz_3d(young_modulus: float = 1000.0, poisson_ratio: float = 0.3, radius: float = 1.0,
             approach: float = 0.02, half_size: float = 2.0, initial_divisions: int = 8,
             friction: str = "none", mu: float = 0.0, slip_bound: float = 0.0,
             slide: float = 0.0) -> Scene:
    if not (is_integer(initial_divisions) and initial_divisions >= 2
            and initial_divisions % 2 == 0):
        raise SceneError(f"initial_divisions={initial_divisions!r} is not an even integer >= 2")
    W = D = float(half_size)
    material = Material(young_modulus, poisson_ratio, "strain")
    law = friction_law(friction, mu, slip_bound, slide=slide)
    # the frictionless scene keeps its parameters (and its cached references' keys)
    with_friction = ({"friction": friction, "mu": float(mu), "slip_bound": float(slip_bound),
                      "slide": float(slide)} if law.active else {})
    xs = np.linspace(-W, W, int(initial_divisions) + 1)
    zs = np.linspace(-D, 0.0, int(initial_divisions) // 2 + 1)
    return Scene(
        name="hertz-3d",
        description="block (-W,W)^2x(-D,0) pressed up by the paraboloid z = r^2/(2R) - delta - D",
        mesh=tensor_mesh(xs, xs, zs),
        material=material,
        is_dirichlet=lambda x: np.abs(x[2]) < _TOL,
        is_contact=lambda x: np.abs(x[2] + D) < _TOL,
        gap=lambda x: (x[0] ** 2 + x[1] ** 2) / (2 * radius) - approach,
        contact_coordinate=lambda x: np.asarray(x)[:2],
        parameters={"young_modulus": young_modulus, "poisson_ratio": poisson_ratio,
                    "radius": radius, "approach": approach, "half_size": half_size,
                    "initial_divisions": initial_divisions, **with_friction},
        tags=("exact", "hertz", "3d"),
        predict_contact=lambda force: hertz_sphere(young_modulus, poisson_ratio, radius, force),
        friction=law,
        predict_stick=(functools.partial(mindlin(mu, law.slide), material, radius)
                       if law.kind == "coulomb" and law.slide else None),
    )

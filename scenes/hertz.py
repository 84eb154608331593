"""``hertz``: Hertz's line contact, as Hertz modelled it.

Hertz's 2D theory (K. L. Johnson, Contact Mechanics, 1985, sections 4.2 and 5.3) treats a
cylinder of radius R on a rigid flat as an elastic half-space with the parabolic gap
g(x) = x^2 / (2 R) - delta. That is exactly what this scene discretises: a block
(-W, W) x (-D, 0) clamped on top, pushed up along its bottom edge by a rigid parabola with
approach delta, plane strain, traction-free sides. With the contact force P per unit thickness
and E* = E / (1 - nu^2) (a rigid flat), Hertz gives the contact half-width and peak pressure

    b = sqrt(4 P R / (pi E*)),    p0 = 2 P / (pi b),    p(x) = p0 sqrt(1 - x^2 / b^2),

valid while b << D and b << W (the half-space assumption); the defaults give b ~ 0.1 against
D = W = 2. The approach delta itself has no closed form in 2D (it depends on the body's size),
which is why the comparison is made at the computed force P.

With Coulomb friction (``friction="coulomb"``, ``mu``) the obstacle also slides along x by
``slide``, in the same single step as it presses: the slip is u_t minus the whole slide, as if
both were applied together from the unloaded state. Where the normal-tangential coupling
vanishes (nu -> 1/2) that is Cattaneo and Mindlin's problem: the tangential force Q < mu P
leaves a stick zone |x| < c = b sqrt(1 - Q / (mu P)) and the shear traction
q(x) = mu p0 (sqrt(1 - x^2/b^2) - (c/b) sqrt(1 - x^2/c^2)) (Johnson, section 7.1). For
nu < 1/2 the stick zone shrinks and moves towards the trailing edge; the prediction is then
the coupled half-plane's (``scenes.half_plane``, the same one-step loading), compared at the
computed P and Q.
"""

from __future__ import annotations

import functools

import numpy as np

from scenes.base import (
    ContactPrediction,
    Material,
    Scene,
    SceneError,
    StickPrediction,
    is_integer,
)
from scenes.budget import tensor_mesh
from scenes.corners import Corner
from scenes.friction import friction_law
from scenes.half_plane import coupled_partial_slip_prediction
from scenes.registry import register_scene

_TOL = 1e-10


def hertz_prediction(scene: Scene, contact_force: float) -> dict:
    """Hertz's half-width and peak pressure for the force ``contact_force`` (per thickness)."""
    E, nu = scene.material.young_modulus, scene.material.poisson_ratio
    contact = hertz_contact(E, nu, scene.parameters["radius"], contact_force)
    return {"half_width": contact.half_width, "peak_pressure": contact.peak_pressure,
            "e_star": float(E / (1 - nu**2))}


def hertz_contact(young_modulus: float, poisson_ratio: float, radius: float,
                  contact_force: float) -> ContactPrediction:
    """Hertz's pressure p0 sqrt(1 - (x/b)^2) at the force ``contact_force``."""
    if not contact_force > 0:  # no contact (a constraint that missed it): nothing to predict
        return ContactPrediction(0.0, 0.0, label="no contact force")
    e_star = young_modulus / (1 - poisson_ratio**2)
    b = float(np.sqrt(4 * contact_force * radius / (np.pi * e_star)))
    p0 = float(2 * contact_force / (np.pi * b))
    return ContactPrediction(b, p0, label=f"Hertz, b = {b:.4g}, p0 = {p0:.4g}")


def partial_slip(contact, exponent: float, name: str, mu: float, slide: float):
    """(material, R, P, Q) -> the partial slip under Hertz's pressure ``contact(E, nu, R, P)``:
    the stick zone c = b (1 - |Q| / (mu P))^exponent, the shear traction along the obstacle's
    slide (1/2: Cattaneo-Mindlin's cylinder, 1/3: Mindlin's sphere; Johnson, 7.1 and 7.2)."""
    def predict(scene_material: Material, radius: float, P: float, Q: float) -> StickPrediction:
        hertz = contact(scene_material.young_modulus, scene_material.poisson_ratio, radius, P)
        ratio = float(np.clip(1.0 - abs(Q) / (mu * P), 0.0, 1.0))
        c = hertz.half_width * ratio**exponent
        return StickPrediction(c, hertz.half_width, hertz.peak_pressure, mu,
                               direction=float(np.sign(slide)),
                               label=f"{name}, c = {c:.4g}, b = {hertz.half_width:.4g}")
    return predict


def cattaneo_mindlin(mu: float, slide: float):
    """(P, Q) -> Cattaneo-Mindlin's partial slip under Hertz's pressure: the stick zone
    c = b sqrt(1 - |Q| / (mu P)), the shear traction along the obstacle's slide."""
    return partial_slip(hertz_contact, 0.5, "Cattaneo-Mindlin", mu, slide)


@register_scene("hertz", "Hertz line contact: a block pressed by a rigid parabola of radius R "
                         "(half-space model), plane strain; closed-form width and peak pressure",
                tags=("exact", "hertz"), dim=2)
def hertz(young_modulus: float = 1000.0, poisson_ratio: float = 0.3, radius: float = 1.0,
          approach: float = 0.005, half_size: float = 2.0, initial_divisions: int = 16,
          friction: str = "none", mu: float = 0.0, slip_bound: float = 0.0,
          slide: float = 0.0) -> Scene:
    if not (is_integer(initial_divisions) and initial_divisions >= 2
            and initial_divisions % 2 == 0):
        raise SceneError(f"initial_divisions={initial_divisions!r} is not an even integer >= 2")
    initial_divisions = int(initial_divisions)
    W = D = float(half_size)
    material = Material(young_modulus, poisson_ratio, "strain")
    law = friction_law(friction, mu, slip_bound, slide=slide)
    # the frictionless scene keeps its parameters (and its cached references' keys)
    with_friction = ({"friction": friction, "mu": float(mu), "slip_bound": float(slip_bound),
                      "slide": float(slide)} if law.active else {})
    xs = np.linspace(-W, W, initial_divisions + 1)
    ys = np.linspace(-D, 0.0, initial_divisions // 2 + 1)
    return Scene(
        name="hertz",
        description="block (-W,W)x(-D,0) pressed up by the parabola y = x^2/(2R) - delta - D",
        mesh=tensor_mesh(xs, ys), material=material,
        is_dirichlet=lambda x: np.abs(x[1]) < _TOL,
        is_contact=lambda x: np.abs(x[1] + D) < _TOL,
        gap=lambda x: x[0] ** 2 / (2 * radius) - approach,
        contact_coordinate=lambda x: x[0],
        parameters={"young_modulus": young_modulus, "poisson_ratio": poisson_ratio,
                    "radius": radius, "approach": approach, "half_size": half_size,
                    "initial_divisions": initial_divisions, **with_friction},
        tags=("exact", "hertz"),
        predict_contact=lambda force: hertz_contact(young_modulus, poisson_ratio, radius, force),
        corners=(Corner((-W, 0.0), np.pi / 2, ("clamped", "free")),
                 Corner((W, 0.0), np.pi / 2, ("clamped", "free"))),
        friction=law,
        # the coupled half-plane (scenes.half_plane, docs/theory.md 19.4): nu < 1/2 here, so
        # Cattaneo-Mindlin's uncoupled answer is never the scene's
        predict_stick=(functools.partial(coupled_partial_slip_prediction(mu, law.slide),
                                         material, radius)
                       if law.kind == "coulomb" and law.slide else None),
    )

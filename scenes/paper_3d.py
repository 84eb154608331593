"""``paper-3d``: the seed paper's scene lifted to 3D (docs/theory.md, section 14.4).

Omega = (-1, 1)^3, Gamma_C the bottom face (outer normal (0, 0, -1)), Gamma_D the top face,
traction-free sides, f = 0, E = 70000 N/mm^2, nu = 0.33 (3D elasticity). The obstacle is the
ball of radius 1 centred at (0, 0, -1.85): its surface z = sqrt(1 - r^2) - 1.85 gives the
linearised gap g(x, y) = 0.85 - sqrt(1 - r^2) along n = (0, 0, -1), r^2 = x^2 + y^2.
Frictionless by default; ``friction``, ``mu`` and ``slip_bound`` give it a friction law
(scenes.friction), as for ``paper``.
"""

from __future__ import annotations

import numpy as np

from scenes.base import Material, Scene, SceneError, is_integer
from scenes.budget import tensor_mesh
from scenes.friction import friction_law
from scenes.registry import register_scene

_TOL = 1e-10


def ball_gap(x: np.ndarray) -> np.ndarray:
    """g = 0.85 - sqrt(1 - x^2 - y^2); negative near the axis (the ball pushes up)."""
    return 0.85 - np.sqrt(np.clip(1.0 - x[0] ** 2 - x[1] ** 2, 0.0, None))


@register_scene("paper-3d", "the seed paper's scene in 3D: the cube (-1,1)^3 clamped on top, "
                            "pressed up by a ball",
                tags=("paper", "3d"), dim=3)
def paper_3d(young_modulus: float = 70000.0, poisson_ratio: float = 0.33,
             initial_divisions: int = 4, friction: str = "none", mu: float = 0.0,
             slip_bound: float = 0.0) -> Scene:
    if not (is_integer(initial_divisions) and initial_divisions >= 2):
        raise SceneError(f"initial_divisions={initial_divisions!r} is not an integer >= 2")
    grid = np.linspace(-1.0, 1.0, int(initial_divisions) + 1)
    law = friction_law(friction, mu, slip_bound)
    # the frictionless scene keeps its parameters, and so its cached references' keys
    with_friction = ({"friction": friction, "mu": float(mu), "slip_bound": float(slip_bound)}
                     if law.active else {})
    return Scene(
        name="paper-3d",
        description="Omega=(-1,1)^3 clamped on top, pressed up by the ball of radius 1 centred "
                    "at (0, 0, -1.85)",
        mesh=tensor_mesh(grid, grid, grid),
        material=Material(young_modulus, poisson_ratio, "strain"),
        is_dirichlet=lambda x: np.abs(x[2] - 1.0) < _TOL,
        is_contact=lambda x: np.abs(x[2] + 1.0) < _TOL,
        gap=ball_gap,
        contact_coordinate=lambda x: np.asarray(x)[:2],
        parameters={"young_modulus": float(young_modulus), "poisson_ratio": float(poisson_ratio),
                    "initial_divisions": int(initial_divisions), **with_friction},
        tags=("paper", "3d"),
        friction=law,
    )

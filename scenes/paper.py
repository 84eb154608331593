"""The ``paper`` scene: section 5 of the seed paper (docs/theory.md, section 2).

Omega = (-1, 1)^2, Gamma_C the bottom edge (outer normal (0, -1)), Gamma_D the top edge, traction
free sides, f = 0, plane stress, E = 70000 N/mm^2, nu = 0.33. The obstacle surface
y = sqrt(1 - x^2) - 1.85 gives the linearised gap g(x) = 0.85 - sqrt(1 - x^2) along n = (0, -1).
Frictionless by default; ``friction``, ``mu`` and ``slip_bound`` give it a friction law
(scenes.friction).
"""

from __future__ import annotations

import numpy as np

from scenes.base import Material, Scene, SceneError, is_integer
from scenes.budget import tensor_mesh
from scenes.corners import Corner
from scenes.friction import friction_law
from scenes.registry import register_scene

_TOL = 1e-10


def paper_gap(x: np.ndarray) -> np.ndarray:
    """g(x) = 0.85 - sqrt(1 - x_1^2); negative near x_1 = 0 (the obstacle pushes up)."""
    return 0.85 - np.sqrt(np.clip(1.0 - x[0] ** 2, 0.0, None))


@register_scene("paper", "Schroeder's square pressed up by a circular obstacle "
                         "(seed paper, section 5)",
                tags=("paper",), dim=2)
def paper(young_modulus: float = 70000.0, poisson_ratio: float = 0.33, plane: str = "stress",
          initial_divisions: int = 4, friction: str = "none", mu: float = 0.0,
          slip_bound: float = 0.0) -> Scene:
    if not (is_integer(initial_divisions) and initial_divisions >= 2):
        raise SceneError(f"initial_divisions={initial_divisions!r} is not an integer >= 2")
    grid = np.linspace(-1.0, 1.0, int(initial_divisions) + 1)
    mesh = tensor_mesh(grid, grid)
    law = friction_law(friction, mu, slip_bound)
    # the frictionless scene's parameters stay as they were, so that its cached references and
    # earlier results keep their keys
    with_friction = ({"friction": friction, "mu": float(mu), "slip_bound": float(slip_bound)}
                     if law.active else {})
    return Scene(
        name="paper",
        description="Omega=(-1,1)^2 clamped on top, pressed up by the obstacle "
                    "y = sqrt(1-x^2) - 1.85 along the bottom edge",
        mesh=mesh,
        material=Material(young_modulus, poisson_ratio, plane),
        is_dirichlet=lambda x: np.abs(x[1] - 1.0) < _TOL,
        is_contact=lambda x: np.abs(x[1] + 1.0) < _TOL,
        gap=paper_gap,
        contact_coordinate=lambda x: x[0],
        # plain Python numbers, so that the reference cache key does not depend on their type
        parameters={"young_modulus": float(young_modulus), "poisson_ratio": float(poisson_ratio),
                    "plane": plane, "initial_divisions": int(initial_divisions),
                    **with_friction},
        tags=("paper",),
        # the clamped top edge meets the traction-free sides at right angles
        corners=(Corner((-1.0, 1.0), np.pi / 2, ("clamped", "free")),
                 Corner((1.0, 1.0), np.pi / 2, ("clamped", "free"))),
        friction=law,
    )

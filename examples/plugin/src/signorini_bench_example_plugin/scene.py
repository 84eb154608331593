"""``punch``: a 2 x 1 block clamped on its bottom, pushed down on its top by a rigid flat punch
of half-width 0.5 with rounded edges (contact on the top edge, outer normal (0, 1))."""

import numpy as np
from skfem import MeshTri

from scenes import Material, Scene, register_scene


@register_scene("punch", "example plugin: a block pushed down by a flat punch with rounded "
                         "edges")
def punch(depth: float = 0.01, young_modulus: float = 1000.0) -> Scene:
    mesh = MeshTri.init_tensor(np.linspace(-1.0, 1.0, 9), np.linspace(0.0, 1.0, 5))
    # the punch's face y = 1 - depth for |x| <= 0.5, rising as (|x| - 0.5)^2 beyond
    rise = lambda x: np.clip(np.abs(x[0]) - 0.5, 0.0, None) ** 2  # noqa: E731
    return Scene(
        name="punch", description="2 x 1 block clamped below, pushed down by a flat punch",
        mesh=mesh, material=Material(young_modulus, 0.3, "strain"),
        is_dirichlet=lambda x: np.abs(x[1]) < 1e-10,
        is_contact=lambda x: np.abs(x[1] - 1.0) < 1e-10,
        gap=lambda x: rise(x) - depth,
        contact_coordinate=lambda x: x[0],
        parameters={"depth": float(depth), "young_modulus": float(young_modulus)})

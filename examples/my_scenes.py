"""A scene defined outside the package, for ``--scene-file examples/my_scenes.py``:

    python -m bench run --scene-file examples/my_scenes.py --scene wide-block \
        --solver active-set --strategy uniform,adaptive --max-dofs 5000

A 4 x 1 block clamped on top and pressed up along its bottom edge by the bump
y = depth - x^2 / 8 (gap g = y_body - y_obstacle = x^2 / 8 - depth along n = (0, -1)).
"""

import numpy as np

from scenes import register_scene
from scenes.base import Material, Scene
from scenes.budget import tensor_mesh


@register_scene("wide-block", "example scene file: a 4 x 1 block pressed up by a parabolic bump",
                dim=2)
def wide_block(young_modulus: float = 1000.0, depth: float = 0.01) -> Scene:
    mesh = tensor_mesh(np.linspace(-2.0, 2.0, 17), np.linspace(0.0, 1.0, 5))
    return Scene(
        name="wide-block",
        description="4 x 1 block clamped on top, pressed up by the bump y = depth - x^2 / 8",
        mesh=mesh,
        material=Material(young_modulus, 0.3, "strain"),
        is_dirichlet=lambda x: np.abs(x[1] - 1.0) < 1e-10,
        is_contact=lambda x: np.abs(x[1]) < 1e-10,
        gap=lambda x: x[0] ** 2 / 8.0 - depth,
        contact_coordinate=lambda x: x[0],
    )

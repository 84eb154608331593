"""The friction figures: the 2D shear curve and the 3D state maps, from artifacts a solve
wrote (bench/matrix/artifacts.friction_fields)."""

import numpy as np

from bench.matrix.artifacts import friction_fields
from bench.report.friction_figures import shear_traction, state_maps
from formulations import get_formulation, solve
from scenes import get_scene


def artifact(scene_name: str, formulation: str, refinements: int) -> dict:
    scene = get_scene(scene_name)
    sol = solve(get_formulation(formulation)(scene, scene.mesh.refined(refinements)),
                "active-set")
    return dict(ndofs=sol.elasticity.ndofs, **friction_fields(sol))


def test_3d_fields_have_one_entry_per_friction_point_and_draw_a_map_per_formulation():
    data = artifact("stick-slip-3d", "vi", 1)
    m = data["friction_state"].size
    assert data["friction_coordinate"].shape == (2, m)
    assert data["friction_bound"].shape == data["friction_shear_size"].shape == (m,)
    # the traction never exceeds its bound (the solve's dual feasibility, round-off)
    assert np.all(data["friction_shear_size"] <= data["friction_bound"] * (1 + 1e-9) + 1e-15)
    assert "friction_shear" not in data  # the 2D curve's field: no curve in 3D
    artifacts = {("vi", "residual", "adaptive"): data,
                 ("penalty", "residual", "adaptive"): data}
    figure = state_maps(artifacts, (0.3, 0.6))
    drawn = [ax for ax in figure.axes if ax.collections]
    assert len(drawn) == 2 and len(drawn[0].patches) == 2  # the two exact circles
    assert shear_traction(artifacts) is None


def test_2d_fields_draw_the_shear_curve_and_no_map():
    data = artifact("stick-slip", "vi", 2)
    artifacts = {("vi", "residual", "adaptive"): data}
    assert data["friction_shear"].shape == data["friction_state"].shape
    assert shear_traction(artifacts) is not None and state_maps(artifacts) is None

"""Scene catalogue: what the problem is (docs/theory.md, section 2).

Importing this package registers every scene module listed below; adding a scene is one new
module with a ``@register_scene`` factory and one import line here.
"""

from scenes import (  # noqa: F401  (register themselves)
    free_boundary,
    free_boundary_3d,
    hard,
    hard_3d,
    hertz,
    hertz_3d,
    paper,
    paper_3d,
    stick_slip,
    stick_slip_3d,
)
from scenes.base import ContactPrediction, ExactSolution, Material, Scene, SceneError
from scenes.registry import get_scene, register_scene, scene_descriptions, scene_names

__all__ = ["ContactPrediction", "ExactSolution", "Material", "Scene", "SceneError", "get_scene",
           "register_scene", "scene_descriptions", "scene_names"]

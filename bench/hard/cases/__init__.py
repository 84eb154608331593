"""The hard-case catalogue: one module per case, each registering itself with
``@hard_case``; every scene tagged ``hard`` is a case through ``scenes.scene_case``. Adding a
case is one new module here and one import line below."""

from bench.hard.cases import (  # noqa: F401
    cycling,
    friction,
    goal_estimate,
    invalid,
    lost_contact,
    mixed_patches_3d,
    mixed_ratio,
    nitsche_gamma,
    penalty_eps,
    scale,
)
from bench.hard.cases.scenes import scene_case

__all__ = ["scene_case"]

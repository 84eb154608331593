"""The hard-case catalogue: one module per case, each registering itself with
``@hard_case``; every scene tagged ``hard`` is a case through ``scenes.scene_case``. Adding a
case is one new module here and one import line below."""

from bench.hard.cases import cycling, invalid, mixed_ratio, penalty_eps, scale  # noqa: F401
from bench.hard.cases.scenes import scene_case

__all__ = ["scene_case"]

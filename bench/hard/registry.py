"""The hard-case registry: every scene tagged ``hard`` is a case of its own (``cases.scenes``),
and ``@hard_case(name, description)`` registers any other (one file in ``bench/hard/cases``).
``hard_case_names`` reads both at call time, so a scene or case registered later is listed
(and run by ``bench.hard.run``) too."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from scenes import scene_descriptions, scene_names
from scenes.registry import Registry, scene_tags

HARD_CASES = Registry("hard case")
hard_case = HARD_CASES.register
HARD_TAG = "hard"


@dataclass(frozen=True)
class CaseFigure:
    """A hard case's own figure: ``draw(rows)`` gets the case's rows of the hard table and
    returns a matplotlib Figure, or None when they hold nothing to draw."""

    draw: Callable
    caption: str


CASE_FIGURES = Registry("hard case figure")  # case name -> its CaseFigure


def case_figure(case: str, caption: str):
    """Register ``draw`` as the figure of ``case`` (the report shows it with ``caption``)."""
    def decorate(draw: Callable) -> Callable:
        CASE_FIGURES.register(case, caption)(CaseFigure(draw, caption))
        return draw
    return decorate


def hard_scene_names() -> list[str]:
    """The scenes whose registration declares the ``hard`` tag (none is built to ask)."""
    return [name for name in scene_names() if HARD_TAG in scene_tags(name)]


def hard_case_names() -> list[str]:
    """The hard scenes, then the other registered cases."""
    return hard_scene_names() + HARD_CASES.names()


def hard_case_descriptions() -> dict[str, str]:
    scenes = scene_descriptions()
    return {**{name: f"scene {name!r}: {scenes[name]}" for name in hard_scene_names()},
            **HARD_CASES.descriptions()}


def case_seconds(name: str) -> float:
    """What a case's registration says it costs (``meta={"seconds": ...}``; 0 if it did not
    say, as the hard scenes, a second or two each, do not)."""
    return float(HARD_CASES.meta(name, "seconds", 0.0)) if name in HARD_CASES.names() else 0.0

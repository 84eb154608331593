"""What a solved level adds to its row beyond its basic numbers, what it is marked by and
whether the sequence ends there (docs/theory.md, sections 7 and 20)."""

from __future__ import annotations

from dataclasses import dataclass

from bench.sequence.columns import solved_columns
from bench.sequence.goal import goal_level, marking_indicators
from scenes import Scene


def target_reason(config, est) -> str | None:
    """Why the sequence ends at this level: its guaranteed bound reached
    ``config.target_error``; None if it did not."""
    if config.target_error is None or not est.guaranteed or est.eta > config.target_error:
        return None
    return f"target reached: guaranteed eta={est.eta:.4g} <= {config.target_error:g}"


@dataclass(frozen=True, eq=False)
class JudgedLevel:
    """A solved level's columns beyond its basic numbers, what it is marked by (None: the
    estimate's indicators), the note on that and why the sequence ends here (or None)."""

    numbers: dict
    indicators: object
    note: str
    reached: str | None


def judge_level(scene: Scene, disc, sol, est, config, options: dict, truth,
                crosscheck: bool) -> JudgedLevel:
    """The solved level's columns (``solved_columns``, the goal's), its marking indicators
    and the target reason."""
    goal = goal_level(scene, sol, config, truth, options.get("backend"), est)
    numbers = dict(solved_columns(scene, disc, sol, est, config, options, truth, crosscheck),
                   **goal.columns)
    indicators, note = marking_indicators(config, est, goal)
    return JudgedLevel(numbers, indicators, note, target_reason(config, est))

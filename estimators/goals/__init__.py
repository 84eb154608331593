"""Goal-oriented error estimation (docs/theory.md, section 20): importing the package registers
every goal estimator, one module and one import line each."""

from estimators.goals import dwr  # noqa: F401  (registers itself)
from estimators.goals.base import (
    DEFAULT_GOAL_ESTIMATOR,
    GoalEstimate,
    goal_estimator_descriptions,
    goal_estimator_names,
    register_goal_estimator,
    why_no_goal_estimate,
)

__all__ = ["DEFAULT_GOAL_ESTIMATOR", "GoalEstimate", "goal_estimator_descriptions",
           "goal_estimator_names", "register_goal_estimator", "why_no_goal_estimate"]

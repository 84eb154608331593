"""A sequence's quantity of interest (docs/theory.md, section 20): its value, true error and
goal estimate on every solved level, and the indicators the ``goal`` strategy marks by.

A run's ``goal`` (a quantity of ``estimators.quantities``) gives every row its ``qoi``
columns; the strategy ``goal`` refines by the goal estimator's indicators (default: the run's
goal, else the contact force), the strategy ``adaptive`` by the energy estimator's, so that a
run compares energy-driven and goal-driven meshes for the same quantity.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from estimators.goals import DEFAULT_GOAL_ESTIMATOR, why_no_goal_estimate
from estimators.goals.base import GOAL_ESTIMATORS
from estimators.goals.force_interval import force_interval, why_no_interval
from estimators.quantities import DEFAULT_QUANTITY, get_quantity
from estimators.quantities.base import QUANTITIES
from formulations.cells import family_of

GOAL_STRATEGY = "goal"


def goal_of(config) -> str | None:
    """The quantity a sequence measures: the run's ``goal``; with the goal strategy and no
    goal given, the contact force; else None."""
    return sequence_goal(config.goal, config.strategy)


def sequence_goal(goal: str | None, strategy: str) -> str | None:
    """``goal_of`` from the run's goal and the sequence's strategy."""
    if goal:
        return goal
    return DEFAULT_QUANTITY if strategy == GOAL_STRATEGY else None


def why_no_goal(scene, goal: str | None, strategy: str, order: int, family) -> str | None:
    """Why a sequence with the run's ``goal`` cannot run: its quantity does not apply to the
    scene, or (goal strategy) its estimator cannot estimate it; a sequence that only measures
    its goal runs without the estimate (its rows say why in ``goal_status``)."""
    goal = sequence_goal(goal, strategy)
    if goal is None:
        return None
    why = QUANTITIES.why_not(goal, scene=scene)
    if why is None and strategy == GOAL_STRATEGY:
        why = why_no_goal_estimate(DEFAULT_GOAL_ESTIMATOR, scene, get_quantity(goal, scene),
                                   order, family)
    return None if why is None else f"goal {goal}: {why}"


@dataclass(frozen=True, eq=False)
class GoalLevel:
    """One level's goal: the columns of its row and the goal estimate (None if there is
    none: its reason is in the columns' ``goal_status``)."""

    columns: dict
    estimate: object | None


def goal_level(scene, solution, config, truth, backend: str | None = None,
               energy=None) -> GoalLevel:
    """The goal columns of a solved level (docs/columns.md); ``energy``: the level's energy
    estimate, whose guaranteed bound gives the contact force its guaranteed interval."""
    goal = goal_of(config)
    if goal is None:
        return GoalLevel({}, None)
    start = time.perf_counter()
    quantity = get_quantity(goal, scene)
    value = float(quantity.evaluate(solution))
    true = quantity.true_value(truth)
    columns = dict(goal_estimator=DEFAULT_GOAL_ESTIMATOR, qoi=value,
                   qoi_exact=math.nan if quantity.exact is None else quantity.exact)
    if true is not None and math.isfinite(true):
        columns.update(qoi_true=true, qoi_error=true - value,
                       qoi_relative_error=abs(true - value) / abs(true) if true else math.nan)
    estimate, columns["goal_status"] = goal_estimate(scene, solution, quantity, config, backend)
    if estimate is not None:
        columns.update(estimate_columns(estimate, columns.get("qoi_error", math.nan)))
    if quantity.energy_interval and energy is not None and energy.guaranteed:
        columns.update(interval_columns(solution, energy.eta, columns.get("qoi_true"),
                                        backend))
    columns["t_goal"] = time.perf_counter() - start
    return GoalLevel(columns, estimate)


def goal_estimate(scene, solution, quantity, config, backend):
    """(GoalEstimate, "") or (None, why there is none)."""
    name = DEFAULT_GOAL_ESTIMATOR
    why = why_no_goal_estimate(name, scene, quantity, config.order,
                               family_of(solution.elasticity.mesh))
    if why is not None:
        return None, why
    try:
        return GOAL_ESTIMATORS.get(name)(scene, solution, quantity, backend), ""
    except Exception as error:  # noqa: BLE001 - recorded in the row, the level stays
        return None, f"{type(error).__name__}: {error}"


def estimate_columns(estimate, error: float) -> dict:
    """The estimate's columns and its effectivity estimate / true error."""
    out = dict(qoi_estimate=estimate.estimate, qoi_residual_part=estimate.residual_part,
               qoi_contact_part=estimate.contact_part, dual_dofs=estimate.dual_dofs)
    if math.isfinite(error) and error != 0:
        out.update(qoi_effectivity=estimate.estimate / error,
                   qoi_sign_right=bool(np.sign(estimate.estimate) == np.sign(error)))
    return out


def interval_columns(solution, energy_bound: float, true: float | None,
                     backend: str | None) -> dict:
    """The guaranteed interval of the contact force (``force_interval``) and whether it
    holds the truth's value; empty where it cannot be had."""
    if why_no_interval(solution) is not None:
        return {}
    interval = force_interval(solution, energy_bound, backend)
    out = dict(qoi_guaranteed=True, qoi_lower=interval.lower, qoi_upper=interval.upper)
    if true is not None and math.isfinite(true):
        out["qoi_interval_holds"] = bool(interval.lower <= true <= interval.upper)
    return out


def marking_indicators(config, estimate, goal: GoalLevel) -> tuple[np.ndarray, str]:
    """What a level marks by: the energy estimate's indicators, or with the goal strategy the
    goal estimate's (the energy's, said in the note, where the goal has none or they vanish:
    no contact set yet)."""
    if config.strategy != GOAL_STRATEGY:
        return estimate.indicators, ""
    if goal.estimate is None:
        return estimate.indicators, "goal indicators missing: marked by the energy estimate"
    if not np.any(goal.estimate.indicators > 0):
        return estimate.indicators, "goal indicators vanish: marked by the energy estimate"
    return goal.estimate.indicators, ""

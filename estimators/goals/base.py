"""The estimate of a quantity of interest's error, and the registry of goal-oriented estimators
(docs/theory.md, section 20). A goal estimator is ``estimate(scene, solution, quantity,
backend=None) -> GoalEstimate``, one module and one ``register_goal_estimator`` each."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from formulations.cells import family_of
from formulations.registry import frictionless_only
from scenes.registry import Registry

GOAL_ESTIMATORS = Registry("goal estimator")
goal_estimator_names = GOAL_ESTIMATORS.names
goal_estimator_descriptions = GOAL_ESTIMATORS.descriptions
DEFAULT_GOAL_ESTIMATOR = "dwr"


@dataclass(frozen=True, eq=False)
class GoalEstimate:
    """``estimate`` approximates J(u, lambda) - J(u_h, lambda_h) with its sign: the residual
    part rho(z) plus the contact part (pi, g - u_h.n) on the contact set (docs/theory.md,
    20.2). ``indicators`` (>= 0, per element) are what marking refines by; ``guaranteed``:
    whether the estimate is a proved bound (never for dwr: its dual problem is linearised at
    the discrete contact set; the guaranteed interval of the contact force is
    ``estimators.goals.force_interval``'s)."""

    estimator: str
    quantity: str
    value: float
    estimate: float
    residual_part: float
    contact_part: float
    indicators: np.ndarray
    dual_dofs: int
    seconds: float
    guaranteed: bool = False


def register_goal_estimator(name: str, description: str, applies=None,
                            families: tuple[str, ...] = ("tri", "tet", "quad")):
    """Register a goal estimator; ``applies(scene=..., family=..., order=..., quantity=...)``
    says why it does not run (a scene with friction is refused: its dual problem is not
    built); ``families``: the cell families (``formulations.cells``) it is verified on."""
    return GOAL_ESTIMATORS.register(name, description,
                                    frictionless_only("goal estimator", name, applies),
                                    meta={"families": tuple(families)})


def why_no_goal_estimate(name: str, scene, quantity, order: int, family=None) -> str | None:
    """Why goal estimator ``name`` does not estimate ``quantity`` on ``scene`` at ``order``
    on the cells of ``family`` (default: the scene's own mesh's), or None."""
    family = family_of(scene.mesh) if family is None else family
    if family.name not in GOAL_ESTIMATORS.meta(name, "families", ()):
        return (f"goal estimator {name!r} is not verified on {family.shape} "
                "(docs/theory.md, 20.4)")
    return GOAL_ESTIMATORS.why_not(name, scene=scene, family=family, order=order,
                                   quantity=quantity)

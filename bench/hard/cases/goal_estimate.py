"""The goal estimate where it is hard (docs/theory.md, section 20): the contact force's
dual-weighted estimate against its exact error on free-boundary (its load's jump on element
edges) when the discrete constraint missed the contact (the mixed method's coarsest mesh:
the contact set is where u_h went through), on a coarse mesh, and nearly incompressible
(nu = 0.49); and a quantity or a scene whose dual problem is not built, refused with the
reason. A row's verdict is the estimate's, and its solver column names the goal estimator
(``dwr``; the solves are the active-set solver's): ``accurate`` when estimate / true error lies
in [0.8, 1.25] with the right sign, ``inaccurate`` otherwise (the finding gives both)."""

from __future__ import annotations

import numpy as np

from bench.hard.registry import hard_case
from bench.hard.verdicts import ACCURATE, FAILED, INACCURATE, REFUSED
from estimators.goals import why_no_goal_estimate
from estimators.goals.dwr import estimate
from estimators.quantities import get_quantity
from formulations import STATUS_FAILED, get_formulation, solve
from formulations.registry import FORMULATIONS
from scenes import get_scene

BAND = (0.8, 1.25)  # the effectivity the goal gates ask for (docs/theory.md, 20.5)
# (variant, scene parameters, uniform refinements of the starting mesh)
VARIANTS = (("no contact seen", {}, 0), ("coarse", {}, 2),
            ("nu=0.49", {"poisson_ratio": 0.49}, 3))


def goal_row(scene, formulation: str, variant: str, level: int) -> dict:
    """One formulation's solve and force estimate on ``scene``'s mesh refined ``level``
    times."""
    mesh = scene.mesh.refined(level) if level else scene.mesh
    solution = solve(get_formulation(formulation)(scene, mesh, order=1), "active-set")
    row = dict(case="goal-estimate", scene=scene.name, formulation=formulation,
               solver="dwr", variant=variant, level=level,
               ndofs=solution.elasticity.ndofs, status=solution.status, reason=solution.reason)
    if solution.status == STATUS_FAILED:
        return {**row, "verdict": FAILED, "finding": "no solution"}
    quantity = get_quantity("contact-force", scene)
    goal = estimate(scene, solution, quantity)
    error = quantity.exact - goal.value
    ratio = goal.estimate / error if error else np.nan
    good = BAND[0] <= ratio <= BAND[1]
    return {**row, "contact_force": goal.value, "qoi_error": error,
            "qoi_estimate": goal.estimate, "qoi_effectivity": ratio,
            "verdict": ACCURATE if good else INACCURATE,
            "finding": f"force error {error:+.3g} ({abs(error) / quantity.exact:.1%}), "
                       f"estimate {goal.estimate:+.3g}, effectivity {ratio:.3f}"}


def refused_rows() -> list[dict]:
    """A quantity without a dual problem, and a scene with friction: refused, the reason
    recorded."""
    scene = get_scene("free-boundary", align_jump=1)
    friction = get_scene("stick-slip", friction="tresca")
    cases = (("contact-zone", scene, "contact-zone"), ("friction", friction, "contact-force"))
    return [dict(case="goal-estimate", scene=where.name, formulation="mixed",
                 solver="dwr", variant=variant, level=0, status="refused",
                 verdict=REFUSED, finding=why_no_goal_estimate(
                     "dwr", where, get_quantity(name, where), 1) or "not refused")
            for variant, where, name in cases]


@hard_case("goal-estimate", "the contact force's dual-weighted estimate where the constraint "
                            "missed the contact, on a coarse mesh and at nu = 0.49 (exact "
                            "error), and goals without a dual problem refused",
           meta={"seconds": 6})  # measured on 2 cores
def goal_estimate() -> list[dict]:
    records = []
    for variant, parameters, level in VARIANTS:
        scene = get_scene("free-boundary", align_jump=1, **parameters)
        for formulation in FORMULATIONS.names():
            if FORMULATIONS.why_not(formulation, scene=scene) is None:
                records.append(goal_row(scene, formulation, variant, level))
    return records + refused_rows()

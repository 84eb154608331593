"""The penalty with eps_0 = 1e-1 .. 1e-12: penetration, conditioning and the reference
solver's accuracy (docs/theory.md, section 8)."""

from __future__ import annotations

import numpy as np

from bench.hard.registry import hard_case
from bench.hard.verdicts import solve_both
from scenes import get_scene

EPSILONS_0 = (1e-1, 1e-2, 1e-4, 1e-6, 1e-8, 1e-10, 1e-12)


@hard_case("penalty-eps", "penalty with eps_0 = 1e-1 .. 1e-12 on the paper scene: penetration, "
                          "conditioning, and the reference solver's accuracy")
def penalty_sweep() -> list[dict]:
    scene, records = get_scene("paper"), []
    mesh = scene.mesh.refined(3)
    for eps in EPSILONS_0:
        rows, _ = solve_both("penalty-eps", scene, "penalty", mesh, variant=f"eps_0={eps:g}",
                             level=3, epsilon_0=eps)
        for row in rows:
            row["finding"] = f"penetration {row['penetration']:.2e}" + (
                f", condition {row['condition_estimate']:.2e}"
                if np.isfinite(row["condition_estimate"]) else "")
        records += rows
    return records

"""Young's modulus 1 against 70000: u must agree and the pressure scale with E."""

from __future__ import annotations

import numpy as np

from bench.hard.registry import hard_case
from bench.hard.verdicts import solve_both
from formulations import formulation_names
from scenes import get_scene


@hard_case("scale", "the paper scene with E = 1 and E = 70000: u must agree and the pressure "
                    "scale with E")
def young_scale() -> list[dict]:
    records = []
    for formulation in formulation_names():
        (soft_rows, soft), (stiff_rows, stiff) = (
            solve_both("scale", scene, formulation, scene.mesh.refined(3),
                       variant=f"E={scene.material.young_modulus:g}", level=3)
            for scene in (get_scene("paper", young_modulus=young) for young in (1.0, 70000.0)))
        for k in range(len(soft)):
            du = np.abs(soft[k].u - stiff[k].u).max() / np.abs(stiff[k].u).max()
            df = abs(70000.0 * soft[k].contact_force() / stiff[k].contact_force() - 1)
            for row in (soft_rows[k], stiff_rows[k]):
                row["finding"] = f"u differs by {du:.1e}, 70000 x force by {df:.1e} (relative)"
                row["scale_difference"] = max(du, df)
        records += soft_rows + stiff_rows
    return records

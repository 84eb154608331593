"""Invalid problems must be refused with a clear error before any solve."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from bench.hard.registry import hard_case
from bench.hard.verdicts import FAILED, REFUSED
from formulations import STATUS_OK
from scenes import SceneError, get_scene

INVALID = {  # each must raise SceneError naming the parameter, the value and what is allowed
    "no clamped part": lambda: replace(get_scene("paper"),
                                       is_dirichlet=lambda x: np.zeros(x.shape[1], bool)),
    "nu = 0.5": lambda: get_scene("paper", poisson_ratio=0.5),
    "gap with NaN": lambda: replace(get_scene("paper"),
                                    gap=lambda x: np.where(x[0] > 0.5, np.nan, 0.0)),
    "E = 0": lambda: get_scene("paper", young_modulus=0.0),
}


@hard_case("invalid", "invalid problems (no clamped part, nu >= 0.5, NaN in the gap, E = 0): "
                      "refused before any solve")
def invalid() -> list[dict]:
    records = []
    for variant, build in INVALID.items():
        try:
            build()
            status, reason, result = STATUS_OK, "accepted (should have been refused)", FAILED
        except SceneError as error:
            status, reason, result = REFUSED, str(error), REFUSED
        records.append(dict(case="invalid", scene="paper", formulation="-", solver="-",
                            variant=variant, status=status, reason=reason, verdict=result,
                            finding=reason))
    return records

"""The hard scenes on quadrilaterals: the same formulations and solvers on the cells of the
scene's grid, the variant naming the cells; a shape that cannot carry a scene is one row that
says why, and no verdict is judged on it."""

import numpy as np
import pandas as pd

from bench.hard.cases.scenes import scene_case
from bench.hard.tables import check_expected
from bench.verify.expected import load_expected


def test_a_hard_scene_runs_on_quadrilaterals_with_every_solver_agreeing():
    records = scene_case("corner", "quad")
    assert {r["variant"] for r in records} == {"quad"}
    assert {r["formulation"] for r in records} == {"mixed", "nitsche", "penalty", "vi"}
    # the fast solver and the reference agree on every quadrilateral problem (measured:
    # every verdict accurate, the contact forces equal to 1e-7 relative)
    assert all(r["verdict"] == "accurate" for r in records)


def test_hexahedra_are_one_row_that_says_why_and_judge_nothing():
    records = scene_case("grazing-3d", "quad")
    assert len(records) == 1 and records[0]["status"] == "skipped"
    assert "contact boundary of hexahedra" in records[0]["reason"]
    assert check_expected(pd.DataFrame(records), load_expected().get("hard", [])) == []


def test_a_failed_solve_is_reported_as_a_failure_with_its_reason():
    from types import SimpleNamespace

    from bench.hard.cases.scenes import scene_finding

    row = {"solver": "reference", "reason": "Clarabel: max iterations", "contact_force": np.nan}
    finding = scene_finding(row, SimpleNamespace(status="failed"))
    assert finding == "the reference solve failed: Clarabel: max iterations"

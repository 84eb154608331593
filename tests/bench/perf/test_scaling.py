"""The scaling table's per-phase breakdown of the fast contact solve."""

import pandas as pd
import pytest

from bench.perf.scaling import measure, phase_table, write_scaling
from formulations.solvers.backends import condenses

pytestmark = pytest.mark.skipif(not condenses(None),
                                reason="the phases belong to the condensed route")


def test_phases_account_for_the_fast_solve(tmp_path):
    row = measure("1e4", reference=False)
    phases = {k: v for k, v in row.items() if k.startswith("t_fast_") and k != "t_fast_solve"}
    assert set(phases) == {"t_fast_order", "t_fast_factorise", "t_fast_schur_block",
                           "t_fast_condense", "t_fast_iterate", "t_fast_condition",
                           "t_fast_back_substitute"}
    # the phases are disjoint parts of the solve: together no more than it, and most of it
    # (1e-9 s of slack: a sum of seven differences of clock readings against one difference)
    assert 0.5 * row["t_fast_solve"] <= sum(phases.values()) <= row["t_fast_solve"] + 1e-9
    frame = pd.DataFrame([row])
    frame["fast_over_linear"] = frame["t_fast_solve"] / frame["t_linear_solve"]
    frame["reference_over_fast"] = float("nan")
    assert "schur block [s]" in phase_table(frame)
    text = write_scaling(frame, tmp_path).read_text()
    assert "Phases of the fast contact solve" in text

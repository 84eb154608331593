"""The sequence benchmark: whole sequences timed phase by phase against the finest linear solve."""

import pandas as pd
import pytest

from bench.cli import main
from bench.measure.contact import SOLVED_STATUSES as SOLVED
from bench.perf.sequence import LEVEL_PHASES, measure_sequence, sequence_table, write_sequences


@pytest.fixture(scope="module")
def adaptive():
    return measure_sequence("adaptive", 3000, reference_dofs=20000)  # a small, cheap reference


def test_a_sequence_is_timed_level_by_level_and_phase_by_phase(adaptive):
    assert set(adaptive["status"].split(",")) <= set(SOLVED) and adaptive["levels"] >= 3
    assert adaptive["final_ndofs"] <= 3000
    phases = sum(adaptive[phase] for phase in LEVEL_PHASES) + adaptive["t_store"]
    # the phases are disjoint parts of the sequence: together no more than its wall time
    # (1e-9 s of slack: a sum of differences of clock readings against one difference)
    assert 0 < phases <= adaptive["t_sequence"] + 1e-9
    assert adaptive["t_error"] > 0  # errors against the reference are part of every level
    assert adaptive["sequence_over_linear"] == pytest.approx(
        adaptive["t_sequence"] / adaptive["t_linear_finest"])


def test_the_table_and_the_readme_markers(adaptive, tmp_path):
    frame = pd.DataFrame([adaptive])
    assert "adaptive to 3e3" in sequence_table(frame)
    readme = tmp_path / "README.md"
    readme.write_text("a\n<!-- sequence:start -->\nold\n<!-- sequence:end -->\nb\n")
    write_sequences(frame, tmp_path / "out", readme)
    text = readme.read_text()
    assert "old" not in text and "sequence / linear" in text and text.endswith("b\n")
    assert (tmp_path / "out" / "scaling-sequence.csv").exists()


@pytest.mark.parametrize("budgets", ["1000", "1000,x", "0,1000"])
def test_bad_budgets_are_refused_in_one_line(budgets, capsys):
    with pytest.raises(SystemExit):
        main(["scaling", "--sequence", "--sequence-max-dofs", budgets])
    assert "sequence_max_dofs=" in capsys.readouterr().err


def test_a_quadrilateral_sequence_is_timed_and_named_by_its_cells():
    quad = measure_sequence("adaptive", 3000, reference_dofs=20000, cell="quad")
    assert set(quad["status"].split(",")) <= set(SOLVED)
    assert quad["cell"] == "quad" and quad["levels"] >= 3
    assert "adaptive to 3e3, quad" in sequence_table(pd.DataFrame([quad]))

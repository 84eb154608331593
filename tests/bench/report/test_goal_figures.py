"""The report's quantities of interest: a run with a goal gets the section, one figure per
scene and quantity and the goal table; a run without one gets neither."""

import pytest

from bench.matrix import RunConfig, run
from bench.report.render import write_report


@pytest.fixture(scope="module")
def goal_report(tmp_path_factory):
    out = tmp_path_factory.mktemp("goal")
    result = run(RunConfig(scenes=("free-boundary",), formulations=("mixed",),
                           solvers=("active-set",), estimators=("residual",),
                           strategies=("adaptive", "goal"), goal="contact-force",
                           max_dofs=600, out=str(out / "results")))
    write_report(result.table, out / "report", out / "results")
    return out / "report"


def test_the_section_shows_the_figure_and_the_table(goal_report):
    text = (goal_report / "README.md").read_text()
    assert "### Quantities of interest" in text
    assert "figures/goal-free-boundary-contact-force.png" in text
    assert (goal_report / "figures" / "goal-free-boundary-contact-force.png").stat().st_size > 0
    section = text.split("### Quantities of interest")[1]
    assert "dofs_to_target" in section
    assert any(line.startswith("| free-boundary |") and "| contact-force | mixed " in line
               for line in section.splitlines())
    assert 'id="goals"' in (goal_report / "index.html").read_text()


def test_a_run_without_a_goal_has_no_section(tmp_path):
    result = run(RunConfig(scenes=("free-boundary",), formulations=("mixed",),
                           solvers=("active-set",), estimators=("residual",),
                           strategies=("adaptive",), max_dofs=200,
                           out=str(tmp_path / "results")))
    write_report(result.table, tmp_path / "report", tmp_path / "results")
    assert "Quantities of interest" not in (tmp_path / "report" / "README.md").read_text()

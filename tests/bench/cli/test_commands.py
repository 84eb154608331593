import subprocess
import sys

import pandas as pd
import pytest

from bench.cli import main
from bench.hard import hard_case_names
from bench.measure.contact import SOLVED_STATUSES as SOLVED
from bench.sequence.loop import STRATEGIES
from estimators import estimator_names
from formulations import formulation_names, solver_names
from scenes import scene_names


def run(*args):
    return subprocess.run([sys.executable, "-m", "bench", *args], capture_output=True, text=True,
                          timeout=300)


def test_help_documents_every_option():
    out = run("run", "--help").stdout
    for option in ("--scene", "--formulation", "--solver", "--estimator", "--strategy",
                   "--max-dofs", "--max-levels", "--marking", "--theta", "--out", "--overwrite"):
        assert option in out
    assert "run" in run("--help").stdout


@pytest.mark.parametrize("option, value, plural, valid", [
    ("--scene", "papr", "scenes", scene_names()),
    ("--formulation", "mortar", "formulations", formulation_names()),
    ("--solver", "gurobi", "solvers", solver_names()),
    ("--estimator", "dwr", "estimators", estimator_names()),
    ("--strategy", "random", "strategies", list(STRATEGIES)),
])
def test_unknown_names_list_the_valid_ones(option, value, plural, valid, capsys):
    with pytest.raises(SystemExit) as exit_:
        main(["run", option, value])
    assert exit_.value.code == 2
    assert f"valid {plural}: {', '.join(valid)}" in capsys.readouterr().err


def test_bad_numbers_are_refused(capsys):
    with pytest.raises(SystemExit):
        main(["run", "--max-dofs", "-5"])
    assert "max_dofs='-5' is not a positive integer" in capsys.readouterr().err


def test_run_writes_results_and_prints_progress_and_summary(tmp_path):
    out = tmp_path / "res"
    result = run("run", "--strategy", "uniform,adaptive", "--max-dofs", "600", "--out", str(out))
    assert result.returncode == 0, result.stderr
    assert "level  0  ndofs       40" in result.stdout
    # the default solver is the fast one (the reference is one flag away)
    assert "== paper / mixed / active-set / residual / adaptive" in result.stdout
    table = pd.read_parquet(out / "results.parquet")
    assert set(table["strategy"]) == {"uniform", "adaptive"}
    assert table["status"].isin(SOLVED).all()
    assert len(pd.read_csv(out / "results.csv")) == len(table)


def test_list_prints_registered_names():
    out = run("list").stdout
    for name in ("paper", "mixed", "reference", "residual"):
        assert name in out


def test_hard_runs_the_named_cases_and_checks_their_verdicts(tmp_path):
    result = run("hard", "--case", "invalid,cycling", "--out", str(tmp_path))
    assert result.returncode == 0, result.stderr
    assert "poisson_ratio=0.5 is not < 0.5" in result.stdout
    assert "hard verdicts as expected" in result.stdout
    table = pd.read_csv(tmp_path / "hard.csv")
    assert set(table["case"]) == {"invalid", "cycling"}
    assert (tmp_path / "hard.md").read_text().startswith("| case")


def test_hard_refuses_an_unknown_case(capsys):
    with pytest.raises(SystemExit) as exit_:
        main(["hard", "--case", "wobbly"])
    assert exit_.value.code == 2
    assert (f"unknown hard case 'wobbly'; valid hard cases: {', '.join(hard_case_names())}"
            in capsys.readouterr().err)


def test_the_usage_line_names_the_command_the_user_typed(monkeypatch):
    from bench.cli.parser import build_parser

    monkeypatch.setattr(sys, "argv", ["/usr/local/bin/signorini-bench", "--help"])
    assert build_parser().format_usage().startswith("usage: signorini-bench ")
    monkeypatch.setattr(sys, "argv", ["/repo/bench/__main__.py", "--help"])
    assert build_parser().format_usage().startswith("usage: python -m bench ")

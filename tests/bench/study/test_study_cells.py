"""The rate study on quadrilaterals: ``study --cell quad`` runs the study file's [cells.quad]
setup (the seed's own discretisation) through the matrix and writes the study's report with
the seed's Figures 1 and 2."""

import pandas as pd

from bench.cli import main
from bench.matrix.store import ResultStore
from bench.measure.contact import SOLVED_STATUSES as SOLVED
from bench.study.run import read_study_file


def test_the_quad_study_is_the_seed_s_setup_on_the_matrix():
    config = read_study_file().config("quad")
    assert config.cell == "quad" and config.estimators == ("residual",)
    assert set(config.formulations) == {"vi", "mixed", "mixed:h_over_H=0.25"}
    assert all(run.cells == ("quad",) for run in config.run_configs())
    quick = read_study_file().config("quad", quick=True)
    assert quick.uniform_max_dofs < config.uniform_max_dofs and quick.cell == "quad"


def test_study_cell_quad_writes_its_report(tmp_path, capsys):
    report, out = tmp_path / "report", tmp_path / "results"
    assert main(["study", "--cell", "quad", "--scene", "free-boundary", "--quick",
                 "--out", str(out), "--report", str(report)]) == 0
    assert "wrote" in capsys.readouterr().out
    table = ResultStore(str(out)).table()
    assert set(table["cell"]) == {"quad"} and set(table["estimator"]) == {"residual"}
    assert set(zip(table["formulation"], table["formulation_options"], strict=True)) == {
        ("vi", ""), ("mixed", ""), ("mixed", "h_over_H=0.25")}
    assert set(table["strategy"]) == {"uniform", "adaptive"}
    assert table["status"].isin(SOLVED).all()
    text = (report / "README.md").read_text()
    assert "figures/seed-fig1.png" in text and "h_over_H=0.25" in text
    assert (report / "figures" / "seed-fig2-free-boundary.png").stat().st_size > 10_000
    asymptotic = pd.read_csv(report / "asymptotic.csv")
    assert set(asymptotic["cell"]) == {"quad"}


def test_quadrilaterals_refuse_order_three(tmp_path, capsys):
    assert main(["study", "--cell", "quad", "--order", "3", "--quick",
                 "--out", str(tmp_path / "r"), "--report", str(tmp_path)]) == 2
    assert "order 3 on quadrilaterals" in capsys.readouterr().err

"""The quadrilateral study: every 2D scene with a tensor starting grid runs on quadrilaterals
without a second definition, Q1 converges at O(h) on free-boundary under uniform refinement,
and ``study --cell quad`` writes its report."""

import numpy as np
import pandas as pd
import pytest

from bench.cli import main
from bench.study.quads import as_frame, quad_sequence, slopes, tensor_grid
from scenes import get_scene


def test_the_quadrilateral_grid_is_the_scene_s_own_tensor_grid():
    xs, ys = tensor_grid(get_scene("paper"))
    assert np.allclose(xs, np.linspace(-1, 1, 5)) and np.allclose(ys, np.linspace(-1, 1, 5))
    with pytest.raises(ValueError, match="not a tensor grid"):
        tensor_grid(get_scene("paper-3d"))


def test_q1_converges_at_order_h_on_free_boundary():
    """The exact solution's error, uniform: N^(-1/2) = O(h) (docs/theory.md, section 15)."""
    rows = quad_sequence("free-boundary", "mixed", 1, "uniform", 9000)
    table = as_frame(rows)
    fitted = slopes(table[table["ndofs"] >= 144], "energy_error")
    # measured -0.48 over 144 .. 8320 DOFs; O(h) is -1/2, and -1/4 (h^1/2) must be far off
    assert fitted["slope_all"].iloc[0] == pytest.approx(-0.5, abs=0.08)


def test_study_cell_quad_writes_its_report(tmp_path, capsys):
    report = tmp_path / "report"
    assert main(["study", "--cell", "quad", "--scene", "free-boundary", "--quick",
                 "--report", str(report)]) == 0
    assert "wrote" in capsys.readouterr().out
    table = pd.read_csv(report / "quads.csv")
    assert set(table["method"]) == {"vi", "mixed", "mixed-H4"}
    assert set(table["strategy"]) == {"uniform", "adaptive"}
    assert table["ndofs"].max() <= 9000 and (table["status"] == "ok").all()
    text = (report / "quads.md").read_text()
    assert "slope_last_error" in text and "figures/quad-fig1.png" in text
    assert (report / "figures" / "quad-fig2-free-boundary.png").stat().st_size > 10_000


def test_quadrilaterals_refuse_order_three(tmp_path, capsys):
    assert main(["study", "--cell", "quad", "--order", "3", "--quick",
                 "--report", str(tmp_path)]) == 2
    assert "orders 1 and 2" in capsys.readouterr().err

"""The 3D scaling table: one size measured, its row complete and its solve exact, the table
written and the README block replaced."""

import pandas as pd
import pytest

from bench.perf.scaling_3d import SIZES_3D, measure_3d, paper_3d_problem, write_scaling_3d
from formulations.elasticity import count_free_dofs
from formulations.solvers.backends import available_backends


def test_sizes_give_the_dof_counts_they_name():
    # 3 n (n + 1)^2 unknowns for n = d 2^r cubes per side (the top face clamped); the largest
    # size by its n alone (its mesh has 10^6 tetrahedra)
    for size, n in (("1e4", 14), ("1e5", 32)):
        scene, mesh = paper_3d_problem(size)
        assert count_free_dofs(scene, mesh) == 3 * n * (n + 1) ** 2
    divisions, refinements = SIZES_3D["5e5"]
    assert 3 * (divisions * 2**refinements) * (divisions * 2**refinements + 1) ** 2 == 545832
    with pytest.raises(ValueError, match="size='1e6' is not one of"):
        paper_3d_problem("1e6")


def test_one_3d_size_is_measured_and_written(tmp_path):
    row = measure_3d("1e4")
    assert row["fast_status"] == "ok" and row["fast_max_residual"] < 1e-9
    assert row["ndofs"] == 3 * 14 * 15**2 and row["dim"] == 3
    frame = pd.DataFrame([row])
    frame["fast_over_linear"] = frame["t_fast_solve"] / frame["t_linear_solve"]
    readme = tmp_path / "README.md"
    readme.write_text("a\n<!-- scaling3d:start -->\nold\n<!-- scaling3d:end -->\nb\n")
    text = write_scaling_3d(frame, tmp_path, readme).read_text()
    assert "paper-3d, vi" in text and "memory model [GiB]" in text
    assert "old" not in readme.read_text() and str(row["ndofs"]) in readme.read_text()


@pytest.mark.slow
@pytest.mark.skipif("amg" not in available_backends(), reason="pyamg is not installed")
def test_an_iterative_back_end_reports_its_krylov_iterations(tmp_path):
    row = measure_3d("1e4", backend="amg")
    assert row["fast_status"] == "ok" and row["backend"] == "amg"
    assert row["linear_krylov_iterations"] > 0 and row["fast_krylov_iterations"] > 0
    frame = pd.DataFrame([row])
    frame["fast_over_linear"] = frame["t_fast_solve"] / frame["t_linear_solve"]
    text = write_scaling_3d(frame, tmp_path).read_text()
    assert f"{row['linear_krylov_iterations']} / {row['fast_krylov_iterations']}" in text

"""The budgets count from level 0: a starting mesh over --max-dofs or the memory model is
refused in one line before it is built, for every kind of scene (README, "Reliability")."""

import pytest

from bench.cli import main
from bench.sequence.loop import LoopConfig, run_sequence
from scenes import get_scene
from scenes.registry import SCENES

TOML_SCENE = """name = "huge-block"
[geometry]
rectangle = [[-1, 1], [-1, 1]]
divisions = [{n}, {n}]
[boundary]
clamped = ["top"]
contact = ["bottom"]
[contact]
gap = "x**2 - 0.01"
"""


def test_a_huge_starting_mesh_is_refused_before_a_vertex_is_made(tmp_path, capsys):
    # 20000 x 20000 cells would be 4e8 vertices (about 8 GiB before the first solve); the
    # refusal names the vertex count, which only the check before building knows
    assert main(["run", "--scene", "paper:initial_divisions=20000", "--max-dofs", "300",
                 "--out", str(tmp_path / "r")]) == 2
    err = capsys.readouterr().err
    assert "400,040,001 vertices" in err and "max_dofs=300" in err
    assert not (tmp_path / "r" / "sequences").exists()


def test_a_starting_mesh_over_the_dof_budget_is_refused(tmp_path, capsys):
    # 20 x 20 cells: 21 * 21 vertices, 21 of them clamped on top, two DOFs each: 840
    assert main(["run", "--scene", "paper:initial_divisions=20", "--max-dofs", "300",
                 "--out", str(tmp_path / "r")]) == 2
    err = capsys.readouterr().err
    assert "starts with 840 DOFs" in err and "max_dofs >= 840" in err


def test_a_toml_scene_with_a_huge_grid_is_left_out_when_it_loads(tmp_path, capsys):
    path = tmp_path / "huge.toml"
    path.write_text(TOML_SCENE.format(n=20000))
    assert main(["list", "--scene-file", str(path)]) == 0
    assert "400,040,001 vertices" in capsys.readouterr().err
    path = tmp_path / "large.toml"
    path.write_text(TOML_SCENE.format(n=20).replace("huge-block", "large-block"))
    try:  # it loads, but starts over a small budget
        assert main(["run", "--scene-file", str(path), "--scene", "large-block", "--max-dofs",
                     "300", "--out", str(tmp_path / "r")]) == 2
    finally:
        SCENES.unregister("large-block")
    assert "over max_dofs=300" in capsys.readouterr().err


def test_a_starting_mesh_that_would_not_fit_in_memory_is_refused(tmp_path, capsys):
    assert main(["run", "--scene", "paper-3d", "--formulation", "vi", "--solver", "active-set",
                 "--max-memory", "0.01", "--out", str(tmp_path / "r")]) == 2
    assert "memory: level 0 needs" in capsys.readouterr().err


def test_the_loop_itself_refuses_level_zero_over_the_budget():
    rows = [r.row for r in run_sequence(get_scene("paper"), "mixed", "active-set", "residual",
                                        LoopConfig(max_dofs=10))]
    assert len(rows) == 1 and rows[0].status == "failed" and rows[0].level == 0
    assert rows[0].reason.startswith("budget: the starting mesh has")


@pytest.mark.parametrize("scene", ["free-boundary", "hertz", "paper-3d", "thin"])
def test_every_kind_of_scene_builds_its_start_within_the_budget(scene, tmp_path, capsys):
    """Tensor grids in 2D and 3D, graded ones and the hard scenes share the guard."""
    assert main(["run", "--scene", scene, "--solver", "active-set", "--formulation", "vi",
                 "--max-dofs", "5", "--out", str(tmp_path / "r")]) == 2
    assert "over max_dofs=5" in capsys.readouterr().err

"""The declarative scene examples run through the command line as they stand, and the Gmsh
mesh of ``holed_block.toml`` is what its script writes."""

from pathlib import Path

import pandas as pd
import pytest

from bench.cli import main
from bench.measure.contact import SOLVED_STATUSES as SOLVED
from scenes.mesh_file import read_mesh_file

EXAMPLES = Path(__file__).parents[2] / "examples"


@pytest.mark.parametrize("file, scene", [("pressed_block.toml", "pressed-block"),
                                         ("holed_block.toml", "holed-block")])
def test_the_toml_examples_run_from_the_command_line(tmp_path, file, scene):
    assert main(["run", "--scene-file", str(EXAMPLES / file), "--scene", scene, "--solver",
                 "active-set", "--strategy", "uniform,adaptive", "--max-dofs", "1200",
                 "--out", str(tmp_path)]) == 0
    table = pd.read_csv(tmp_path / "results.csv")
    assert set(table["scene"]) == {scene} and table["status"].isin(SOLVED).all()
    finest = table.groupby("strategy")["active_constraints"].last()
    assert (finest > 0).all()  # the parabola presses (its zone is under one coarse facet)
    assert set(table["strategy"]) == {"uniform", "adaptive"}


def test_the_committed_gmsh_mesh_is_what_its_script_writes(tmp_path):
    gmsh = pytest.importorskip("gmsh", reason="the gmsh package is optional (pip install gmsh)")
    del gmsh
    import importlib.util
    spec = importlib.util.spec_from_file_location(
        "make_holed_block", EXAMPLES / "meshes" / "make_holed_block.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    fresh = read_mesh_file(module.make_holed_block(tmp_path / "fresh.msh"))
    committed = read_mesh_file(EXAMPLES / "meshes" / "holed_block.msh")
    assert fresh.mesh.t.shape == committed.mesh.t.shape
    assert {k: v.shape for k, v in fresh.groups.items()} == \
        {k: v.shape for k, v in committed.groups.items()}
    # Gmsh's mesher is deterministic for one version; across versions the node positions may
    # move by round-off, hence a tolerance of 1e-9 on coordinates of order 1
    assert abs(fresh.mesh.p.sum() - committed.mesh.p.sum()) < 1e-9 * fresh.mesh.p.size

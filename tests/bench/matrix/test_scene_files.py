"""Scenes from a user's file (--scene-file): usable in the CLI, in-process and on Dask, refused
in one line when broken, and part of each sequence's key."""

import json
from pathlib import Path

import pandas as pd

from bench.cli import main
from bench.matrix import RunConfig, run
from bench.matrix.scene_files import source_digest
from bench.measure.contact import SOLVED_STATUSES as SOLVED

EXAMPLE = Path(__file__).parents[3] / "examples" / "my_scenes.py"


def test_the_example_scene_file_runs_from_the_command_line(tmp_path):
    assert main(["run", "--scene-file", str(EXAMPLE), "--scene", "wide-block", "--solver",
                 "active-set", "--strategy", "uniform", "--max-dofs", "600",
                 "--out", str(tmp_path)]) == 0
    table = pd.read_csv(tmp_path / "results.csv")
    assert set(table["scene"]) == {"wide-block"} and table["status"].isin(SOLVED).all()
    assert table["active_constraints"].max() > 0  # the bump presses
    record = json.loads((tmp_path / "run.json").read_text())["configuration"]
    assert record["scene_files"] == [str(EXAMPLE)]


def test_python_and_toml_scene_files_reach_the_dask_workers(tmp_path):
    toml = EXAMPLE.with_name("pressed_block.toml")
    result = run(RunConfig(scenes=("wide-block", "pressed-block"), solvers=("active-set",),
                           strategies=("uniform",), max_dofs=600, workers=1,
                           scene_files=(str(EXAMPLE), str(toml)), out=str(tmp_path)))
    assert all(r.status in SOLVED for r in result.rows)
    # free DOFs, 2 per node off the clamped top: wide-block 17 x 5 and 33 x 9 nodes less 17
    # and 33, pressed-block 9 x 5 and 17 x 9 less 9 and 17
    assert sorted(r.ndofs for r in result.rows) == [72, 136, 272, 528]


def test_a_broken_scene_file_is_named_once_and_left_out(tmp_path, capsys):
    broken = tmp_path / "broken.py"
    broken.write_text("raise RuntimeError('no such obstacle')\n")
    assert main(["list", "--scene-file", str(broken)]) == 0
    captured = capsys.readouterr()
    assert captured.err.count(f"--scene-file={str(broken)!r} failed to load and is left out: "
                              "RuntimeError: no such obstacle") == 1
    assert "Traceback" not in captured.err
    assert f"scene file {str(broken)!r} broken, left out" in captured.out
    assert "  paper " in captured.out  # every other scene is still there
    wrong = tmp_path / "scene.txt"
    wrong.write_text("")
    assert main(["run", "--scene-file", str(wrong)]) == 2
    assert "is not a Python file" in capsys.readouterr().err
    assert main(["run", "--scene-file", str(tmp_path / "missing.py")]) == 2
    assert "does not exist" in capsys.readouterr().err


def test_a_changed_scene_file_changes_the_sequence_keys(tmp_path):
    copy = tmp_path / "scenes_copy.py"
    copy.write_text(EXAMPLE.read_text())
    before = source_digest([copy])
    copy.write_text(EXAMPLE.read_text() + "\n# changed\n")
    assert source_digest([copy]) != before and source_digest([]) == ""
    # without scene files the keys are those of earlier versions (no stale-key churn)
    assert RunConfig().specs()[0].scene_source == ""

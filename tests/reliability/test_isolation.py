"""User code cannot break the suite: a scene, scene file or plugin that fails to build, raises
or exits is named once on stderr and left out, and every other scene and command keeps
working; no command builds every scene to read its tags (docs/reliability.md)."""

import sys

import pytest

import bench.matrix.plugins as plugins
from bench.cli import main
from bench.cli.commands import compared_scenes
from bench.cli.parser import build_parser
from bench.hard import hard_case_names
from scenes import SceneError
from scenes.registry import SCENES, register_scene

INVALID_SCENE = '''
import numpy as np
from skfem import MeshTri
from scenes import Material, Scene, register_scene

@register_scene("{name}", "a scene whose contact boundary is empty")
def invalid():
    grid = np.linspace(0.0, 1.0, 3)
    return Scene(name="{name}", description="no contact", mesh=MeshTri.init_tensor(grid, grid),
                 material=Material(1.0, 0.3, "stress"), is_dirichlet=lambda x: x[1] > 1 - 1e-9,
                 is_contact=lambda x: x[1] < -5.0, gap=lambda x: 0.0 * x[0],
                 contact_coordinate=lambda x: x[0])
'''


@pytest.fixture
def invalid_scene_file(tmp_path):
    path = tmp_path / "invalid_scene.py"
    path.write_text(INVALID_SCENE.format(name="empty-contact"))
    yield path
    SCENES.unregister("empty-contact")


def test_an_invalid_scene_breaks_neither_list_nor_its_siblings(invalid_scene_file, tmp_path,
                                                               capsys):
    files = ["--scene-file", str(invalid_scene_file)]
    assert main(["list", *files]) == 0
    assert "  empty-contact " in capsys.readouterr().out
    assert main(["run", *files, "--scene", "free-boundary", "--solver", "active-set",
                 "--max-dofs", "200", "--out", str(tmp_path / "ok")]) == 0
    capsys.readouterr()
    assert main(["run", *files, "--scene", "empty-contact", "--out", str(tmp_path / "x")]) == 2
    err = capsys.readouterr().err
    assert "contact boundary" in err and "Traceback" not in err and len(err.splitlines()) == 1


def test_a_scene_file_that_exits_is_left_out(tmp_path, capsys):
    exits = tmp_path / "exits.py"
    exits.write_text("import sys\nsys.exit(3)\n")
    assert main(["list", "--scene-file", str(exits)]) == 0
    captured = capsys.readouterr()
    assert captured.err.count("exited and is left out: SystemExit: 3") == 1
    assert "broken, left out" in captured.out


class ExitingEntryPoint:
    """An installed plugin's entry point whose module calls ``sys.exit(3)`` on import."""

    name, group = "exits", "signorini_bench.scenes"
    dist = type("Distribution", (), {"name": "exiting-plugin"})()

    def load(self):
        sys.exit(3)


def test_a_plugin_that_exits_is_skipped(monkeypatch, capsys):
    monkeypatch.setattr(plugins, "entry_points", lambda group: [ExitingEntryPoint()]
                        if group == ExitingEntryPoint.group else [])
    monkeypatch.setattr(plugins, "_LOADED", False)
    monkeypatch.setattr(plugins, "FAILURES", [])
    failures = plugins.load_plugins()
    assert [f.reason for f in failures] == ["SystemExit: 3"]
    assert "'exiting-plugin'" in capsys.readouterr().err
    assert "paper" in SCENES.names()


def test_no_command_builds_every_scene_to_read_its_tags(monkeypatch):
    def refuse():
        raise SceneError("built although only its tags were asked for")

    register_scene("unbuildable", "a scene that cannot be built", tags=("hard",))(refuse)
    try:
        assert "unbuildable" in hard_case_names()
        build_parser()  # the parser lists every scene and hard case
    finally:
        SCENES.unregister("unbuildable")


def test_compare_leaves_out_a_scene_that_fails_to_build(capsys):
    def refuse():
        raise SceneError("no mesh")

    register_scene("fails-to-build", "a user scene of unknown dimension")(refuse)
    try:
        names = compared_scenes(2)
        assert "fails-to-build" not in names and "paper" in names
        assert capsys.readouterr().err.count("'fails-to-build' fails to build") == 1
        with pytest.raises(KeyError, match="is broken"):
            SCENES.get("fails-to-build")
    finally:
        SCENES.unregister("fails-to-build")


def test_every_built_in_scene_builds_as_registered():
    """The registrations' tags and dimension are what the scenes build with (get_scene checks
    it); the hard ones are the hard cases."""
    from scenes import get_scene, scene_names
    from scenes.registry import scene_dim, scene_tags

    for name in scene_names():
        scene = get_scene(name)
        assert scene.dim == scene_dim(name) and set(scene_tags(name)) <= set(scene.tags)


NAN_ON_LEVEL_2 = '''
import numpy as np
from conftest import square_scene
from scenes import register_scene

register_scene("nan-later", "a gap that is NaN at a point of the second refinement")(
    lambda: square_scene(lambda x: np.where(np.abs(x[0] - 0.3125) < 1e-3, np.nan, -0.01),
                         name="nan-later"))
'''


def test_a_scene_that_fails_on_a_refined_level_gives_a_failed_row_not_a_traceback(
        tmp_path, capsys):
    path = tmp_path / "nan_later.py"
    path.write_text(NAN_ON_LEVEL_2)
    try:
        assert main(["run", "--scene-file", str(path), "--scene", "nan-later", "--strategy",
                     "uniform", "--solver", "active-set", "--out", str(tmp_path / "r")]) == 1
    finally:
        SCENES.unregister("nan-later")
    captured = capsys.readouterr()
    assert "Traceback" not in captured.err and "is not finite" in captured.err
    assert "failed" in captured.out

"""Declarative scenes (TOML, optionally on a mesh file): the built-in ``paper`` scene written as
TOML, and on a Gmsh mesh of the same triangles, reproduces the built-in scene's solutions; a bad
file is refused in one line naming the key."""

import meshio
import numpy as np
import pytest

from bench.sequence.loop import LoopConfig, run_sequence
from scenes import SceneError, get_scene
from scenes.declarative import register_toml_scene
from scenes.registry import SCENES

PAPER_TOML = """
name = "{name}"
[geometry]
{geometry}
[material]
young_modulus = 70000.0
poisson_ratio = 0.33
plane = "stress"
[boundary]
clamped = "{clamped}"
contact = "{contact}"
[contact]
gap = "0.85 - sqrt(maximum(1 - x**2, 0))"
"""
RECTANGLE = "rectangle = [[-1.0, 1.0], [-1.0, 1.0]]\ndivisions = [4, 4]"


@pytest.fixture
def registered():
    names = []
    yield names
    for name in names:
        SCENES.unregister(name)


def register(path, text, registered):
    path.write_text(text)
    name = register_toml_scene(path)
    registered.append(name)
    return name


def rows(scene):
    config = LoopConfig(strategy="uniform", max_dofs=600, diagnostics=False)
    return [level.row for level in run_sequence(scene, "mixed", "active-set", "residual",
                                                 config)]


def assert_same_sequence(scene, registered_scene, rtol):
    mine, paper = rows(registered_scene), rows(scene)
    assert [r.ndofs for r in mine] == [r.ndofs for r in paper] == [40, 144, 544]
    for a, b in zip(mine, paper, strict=True):
        for column in ("energy", "contact_force", "eta"):
            assert getattr(a, column) == pytest.approx(getattr(b, column), rel=rtol), column
        assert a.active_constraints == b.active_constraints


def test_paper_as_toml_reproduces_the_builtin_scene(tmp_path, registered):
    name = register(tmp_path / "paper.toml", PAPER_TOML.format(
        name="toml-paper", geometry=RECTANGLE, clamped="top", contact="bottom"), registered)
    # the same mesh and the same arithmetic (np.maximum instead of np.clip): equal to round-off
    assert_same_sequence(get_scene("paper"), get_scene(name), rtol=1e-12)


def test_paper_on_a_gmsh_mesh_reproduces_the_builtin_scene(tmp_path, registered):
    mesh = get_scene("paper").mesh
    boundary = mesh.facets[:, mesh.boundary_facets()].T
    mid = mesh.p[:, boundary].mean(axis=2)
    group = np.select([np.isclose(mid[1], 1), np.isclose(mid[1], -1)], [1, 2], 3)
    points = np.vstack([mesh.p, np.zeros(mesh.p.shape[1])]).T
    meshio.write(tmp_path / "square.msh", meshio.Mesh(
        points, [("line", boundary), ("triangle", mesh.t.T[:, ::-1])],  # clockwise on purpose
        cell_data={"gmsh:physical": [group, np.full(mesh.t.shape[1], 4)],
                   "gmsh:geometrical": [group, np.full(mesh.t.shape[1], 1)]},
        field_data={"top": np.array([1, 1]), "bottom": np.array([2, 1]),
                    "sides": np.array([3, 1]), "body": np.array([4, 2])}),
        file_format="gmsh22", binary=False)
    name = register(tmp_path / "paper_mesh.toml", PAPER_TOML.format(
        name="gmsh-paper", geometry='mesh = "square.msh"', clamped="top", contact="bottom"),
        registered)
    scene = get_scene(name)
    assert scene.mesh.t.shape == mesh.t.shape and scene.neumann_facets().size == 8
    # the same triangles, reoriented and refined in the same order: equal to round-off
    assert_same_sequence(get_scene("paper"), scene, rtol=1e-10)


@pytest.mark.parametrize("table, builtin", [
    ('law = "coulomb"\nmu = "friction_mu"', dict(friction="coulomb", mu=0.3)),
    ('law = "tresca"\nslip_bound = "100 * friction_mu"', dict(friction="tresca",
                                                             slip_bound=30.0)),
])
def test_a_friction_table_reproduces_the_builtin_law(tmp_path, registered, table, builtin):
    text = (PAPER_TOML.format(name="toml-friction", geometry=RECTANGLE, clamped="top",
                              contact="bottom")
            + f"[friction]\n{table}\n[parameters]\nfriction_mu = 0.3\n")
    name = register(tmp_path / "friction.toml", text, registered)
    config = LoopConfig(strategy="uniform", max_dofs=600, diagnostics=False)
    mine, paper = ([level.row for level in run_sequence(scene, "vi", "active-set", "residual",
                                                        config)]
                   for scene in (get_scene(name), get_scene("paper", **builtin)))
    assert [r.ndofs for r in mine] == [r.ndofs for r in paper] == [40, 144, 544]
    for a, b in zip(mine, paper, strict=True):
        assert a.friction == b.friction != "none"
        # the same mesh, law and solver: equal to the fast solver's round-off
        for column in ("energy", "contact_force", "eta"):
            assert getattr(a, column) == pytest.approx(getattr(b, column), rel=1e-9), column
        assert (a.stick_points, a.slip_points) == (b.stick_points, b.slip_points)
    assert mine[-1].slip_points > 0  # the law acts: the body slips somewhere


@pytest.mark.parametrize("table, message", [
    ('law = "stiction"', "[friction] law='stiction' is not one of none, tresca, coulomb"),
    ('law = "coulomb"\nmu = "0.1 * x"', "[friction] mu='0.1 * x' depends on x or y"),
    ('law = "tresca"', "[friction] law='tresca' needs slip_bound"),
    ('law = "coulomb"\nmu = 0.3\nslip_bound = "1"', "slip_bound needs law='tresca'"),
    ('mu = 0.3', "[friction] mu=0.3 needs friction='coulomb'"),
    ('law = "coulomb"', "[friction] mu=0.0 is not in (0, 100]"),
    ('law = "coulomb"\nmu = 0.3\nfriction = 1', "[friction] friction is not one of law"),
])
def test_bad_friction_tables_are_refused_in_one_line(tmp_path, table, message):
    path = tmp_path / "bad.toml"
    path.write_text(PAPER_TOML.format(name="bad", geometry=RECTANGLE, clamped="top",
                                      contact="bottom") + f"[friction]\n{table}\n")
    with pytest.raises(SceneError) as error:
        register_toml_scene(path)
    assert message in str(error.value) and "\n" not in str(error.value)
    assert "bad" not in SCENES.names()


def test_parameters_are_overridable_and_part_of_the_scene(tmp_path, registered):
    text = PAPER_TOML.format(name="toml-depth", geometry=RECTANGLE, clamped="top",
                             contact="bottom").replace(
        '"0.85 - sqrt(maximum(1 - x**2, 0))"', '"x**2 - depth"') + "[parameters]\ndepth = 0.1\n"
    name = register(tmp_path / "depth.toml", text, registered)
    deeper = get_scene(name, depth=0.2)
    assert deeper.gap(np.array([[0.5], [-1.0]]))[0] == pytest.approx(0.25 - 0.2, rel=1e-15)
    assert deeper.parameters["depth"] == 0.2 and len(deeper.parameters["source"]) == 16
    with pytest.raises(SceneError, match="parameter 'width' is not one of its"):
        get_scene(name, width=1.0)


@pytest.mark.parametrize("change, message", [
    (("[geometry]\n", "[geometry]\nmesh = 'a.msh'\n"), "needs exactly one of rectangle, mesh"),
    (("rectangle = [[-1.0, 1.0], [-1.0, 1.0]]", "rectangle = [[1.0, -1.0], [-1.0, 1.0]]"),
     "[geometry] rectangle=[[1.0, -1.0], [-1.0, 1.0]] is not [[x0, x1], [y0, y1]]"),
    (("divisions = [4, 4]", "divisions = [4, 0]"), "divisions=[4, 0] is not [nx, ny]"),
    (('clamped = "top"', 'clamped = "front"'),
     "[boundary] clamped='front' is not one or a list of the sides of the rectangle: left, "
     "right, bottom, top"),
    (('gap = "0.85 - sqrt(maximum(1 - x**2, 0))"', 'gap = "open(x)"'),
     "[contact] gap='open(x)': 'open(x)' is not allowed"),
    (("[contact]\n", "[contact]\ndepth = 1\n"), "[contact] depth is not one of gap, coordinate"),
    (("[material]\n", "[materials]\n"), "key 'materials' is not one of"),
    (("poisson_ratio = 0.33", "poisson_ratio = 0.5"), "poisson_ratio=0.5 is not < 0.5"),
    (('contact = "bottom"', 'contact = "top"'), "dirichlet boundary='overlapping the contact"),
    (('name = "bad"', 'name = "a b"'), "name='a b' is not a non-empty name"),
    (("plane", "plane = = "), "not a readable TOML file"),
])
def test_bad_files_are_refused_in_one_line_naming_the_key(tmp_path, change, message):
    path = tmp_path / "bad.toml"
    text = PAPER_TOML.format(name="bad", geometry=RECTANGLE, clamped="top", contact="bottom")
    path.write_text(text.replace(*change, 1))
    with pytest.raises(SceneError) as error:
        register_toml_scene(path)
    assert message in str(error.value) and "\n" not in str(error.value)
    assert "bad" not in SCENES.names()  # nothing half-registered


def test_a_mesh_without_named_boundaries_is_refused(tmp_path):
    mesh = get_scene("paper").mesh
    meshio.write(tmp_path / "plain.msh", meshio.Mesh(
        np.vstack([mesh.p, np.zeros(mesh.p.shape[1])]).T, [("triangle", mesh.t.T)]),
        file_format="gmsh22", binary=False)
    (tmp_path / "plain.toml").write_text(PAPER_TOML.format(
        name="plain", geometry='mesh = "plain.msh"', clamped="top", contact="bottom"))
    with pytest.raises(SceneError, match="has no named physical groups of lines"):
        register_toml_scene(tmp_path / "plain.toml")
    (tmp_path / "none.toml").write_text(PAPER_TOML.format(
        name="none", geometry='mesh = "missing.msh"', clamped="top", contact="bottom"))
    with pytest.raises(SceneError, match="does not read as a mesh"):
        register_toml_scene(tmp_path / "none.toml")


def test_a_load_jump_is_read_as_an_expression(tmp_path, registered):
    """``[load] load_jump`` becomes the scene's level set, evaluated like any expression;
    without it the scene has none."""
    text = (PAPER_TOML.format(name="toml-jump", geometry=RECTANGLE, clamped="top",
                              contact="bottom")
            + '[load]\nbody_force = ["0", "where(abs(x) < a, -1, 0)"]\n'
            + 'load_jump = "abs(x) - a"\n[parameters]\na = 0.4\n')
    name = register(tmp_path / "jump.toml", text, registered)
    x = np.array([[-0.5, 0.0, 0.4, 0.9], [0.0, 0.3, -0.2, 0.1]])
    assert np.allclose(get_scene(name).load_jump(x), [0.1, -0.4, 0.0, 0.5], atol=1e-15)
    assert get_scene("paper").load_jump is None

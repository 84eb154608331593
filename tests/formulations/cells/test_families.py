"""The cell families: one registration each, found from a mesh or from the cell axis, and
each one's count of unknowns equal to what its assembly gives (counted independently: the
assembly's free DOFs)."""

import numpy as np
import pytest
from skfem import MeshTet, MeshTri

from conftest import square_scene
from formulations.cells import CELL_FAMILIES, cell_names, check_cell, family_for, family_of
from formulations.elasticity import assemble_elasticity, count_free_dofs
from scenes import get_scene
from scenes.hex_hierarchy import HexHierarchy
from scenes.quad_hierarchy import QuadHierarchy


def test_every_family_is_found_from_its_mesh_and_from_the_cell_axis():
    meshes = {"tri": MeshTri(), "tet": MeshTet(),
              "hex": HexHierarchy.from_tensor(*[np.linspace(0, 1, 2)] * 3).mesh(),
              "quad": QuadHierarchy.from_tensor(np.linspace(0, 1, 3),
                                                np.linspace(0, 1, 3)).mesh()}
    assert sorted(meshes) == CELL_FAMILIES.names()
    for name, mesh in meshes.items():
        family = family_of(mesh)
        assert family.name == name and family_for(family.cell, mesh.dim()) is family
    assert cell_names() == ["quad", "tri"]


def test_a_cell_that_no_family_has_is_refused_in_one_line_naming_the_allowed():
    with pytest.raises(ValueError, match="cell='hexagon' is not one of quad, tri"):
        check_cell("hexagon")
    with pytest.raises(ValueError, match="belongs to no cell family"):
        family_of(object())


@pytest.mark.parametrize("name, cell, orders", [
    ("paper", "tri", (1, 2, 3)), ("free-boundary", "quad", (1, 2)),
    ("hertz", "quad", (1, 2)), ("paper-3d", "tri", (1, 2)), ("paper-3d", "quad", (1, 2))])
def test_the_count_of_unknowns_is_the_assemblys(name, cell, orders):
    scene = get_scene(name)
    family = family_for(cell, scene.dim)
    mesh = family.starting_mesh(scene)
    rng = np.random.default_rng(5)
    for _ in range(2):  # the starting mesh and one adaptive refinement
        for order in orders:
            assert count_free_dofs(scene, mesh, order) == assemble_elasticity(
                scene, mesh, order).ndofs
        marked = np.flatnonzero(rng.random(mesh.t.shape[1]) < 0.3)
        plan = family.refinement(mesh, marked)
        assert plan.free_dofs(scene, orders[0]) == count_free_dofs(scene, plan.refined,
                                                                    orders[0])
        mesh = plan.refined


def test_a_scene_whose_mesh_is_not_a_tensor_grid_has_no_quadrilaterals():
    grid = square_scene(lambda x: 0.0 * x[0])
    assert family_for("quad", 2).why_not(grid) is None
    moved = grid.mesh.p.copy()
    moved[0, 7] += 0.01  # one vertex off its grid line: no grid lines give the cells
    scene = square_scene(lambda x: 0.0 * x[0])
    object.__setattr__(scene, "mesh", MeshTri(moved, grid.mesh.t))
    assert "not a tensor grid" in family_for("quad", 2).why_not(scene)
    with pytest.raises(ValueError, match="not a tensor grid"):
        family_for("quad", 2).starting_mesh(scene)


def test_hexahedra_refine_either_way_and_pose_contact_on_their_faces():
    family = family_for("quad", 3)
    for strategy in ("adaptive", "uniform"):
        assert family.why_not(get_scene("paper-3d"), strategy) is None
    assert family.contact_boundary == "quadrilaterals"

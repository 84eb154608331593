"""3D field output and figures: a 3D run's artifacts export as tetrahedra and contact
triangles carrying the run's own arrays, and the report's 3D figures are drawn from them."""

import meshio
import numpy as np
import pytest

from bench.cli import main
from bench.matrix.artifacts import load_artifact
from bench.report.figures_3d import mesh_slices, pressure_maps, slice_polygons
from bench.sequence.loop import LoopConfig, run_sequence
from scenes import get_scene

STEM = "free-boundary-3d-vi-active-set-residual-adaptive-1"


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    out = tmp_path_factory.mktemp("results3d")
    assert main(["run", "--scene", "free-boundary-3d", "--formulation", "vi", "--solver",
                 "active-set", "--strategy", "adaptive", "--max-dofs", "500",
                 "--out", str(out)]) == 0
    return out


def test_3d_fields_read_back_equal_the_runs_own(results, tmp_path):
    assert main(["export", "--results", str(results), "--out", str(tmp_path)]) == 0
    body = meshio.read(tmp_path / f"{STEM}.vtu")
    contact = meshio.read(tmp_path / f"{STEM}-contact.vtu")
    scene = get_scene("free-boundary-3d")
    last = list(run_sequence(scene, "vi", "active-set", "residual",
                             LoopConfig(strategy="adaptive", max_dofs=500)))[-1]
    sol = last.solution
    assert body.cells[0].type == "tetra" and contact.cells[0].type == "triangle"
    np.testing.assert_allclose(body.points, sol.elasticity.mesh.p.T, rtol=0, atol=0)
    # the deterministic solve recomputed: equal to round-off (1e-12 relative)
    u = sol.elasticity.nodal(sol.u).T
    np.testing.assert_allclose(body.point_data["displacement"], u, atol=1e-12 * abs(u).max())
    assert body.cell_data["stress"][0].shape == (sol.elasticity.mesh.t.shape[1], 9)
    pressure = contact.point_data["lambda_h"]
    assert pressure.min() >= 0 and pressure.size == 3 * sol.trace.size


def test_3d_figures_are_drawn_from_the_artifacts(results):
    data = load_artifact(results / "artifacts" / f"{STEM}.npz")
    artifacts = {("vi", "residual", "adaptive", 1): data}
    assert pressure_maps(artifacts) is not None
    assert mesh_slices(artifacts) is not None
    assert pressure_maps({}) is None and mesh_slices({}) is None


def test_the_slice_of_the_cube_is_the_square():
    # every tetrahedron cut by the plane y = 1e-9 gives a triangle or a quadrilateral; their
    # areas add up to the cross-section 2 x 2 of the cube (to round-off)
    mesh = get_scene("paper-3d").mesh.refined()
    area = 0.0
    for polygons, _ in slice_polygons(mesh.p, mesh.t, 1e-9):
        x, z = polygons[..., 0], polygons[..., 1]
        area += 0.5 * np.abs((x * np.roll(z, -1, axis=1) - np.roll(x, -1, axis=1) * z)
                             .sum(axis=1)).sum()
    assert area == pytest.approx(4.0, rel=1e-8)

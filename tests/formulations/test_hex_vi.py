"""The VI on hexahedra (Q1, uniform): a rigid flat pressing a cube up is reproduced exactly,
the active-set solve agrees with Clarabel, and the error against free-boundary-3d's exact
solution falls under refinement."""

import numpy as np
import pytest

from bench.study.quads import hex_error, hex_sequence
from formulations.hex_vi import hex_mesh, solve_hex_vi
from scenes import Material, Scene, get_scene
from scenes.budget import tensor_mesh

TOL = 1e-10


@pytest.fixture
def pushed_cube():
    """(-1,1)^3 clamped on top, pushed up by delta = 0.01 on the bottom, nu = 0:
    u = (0, 0, delta (1 - z) / 2), pressure E delta / 2 = 5 on all 4 of Gamma_C (force 20),
    energy 1/2 (E delta^2 / 4) |Omega| = 0.1; trilinear, so Q1 holds it."""
    grid = np.linspace(-1.0, 1.0, 3)
    return Scene(name="pushed-cube", description="flat push", mesh=tensor_mesh(grid, grid, grid),
                 material=Material(1000.0, 0.0, "strain"),
                 is_dirichlet=lambda x: np.abs(x[2] - 1) < TOL,
                 is_contact=lambda x: np.abs(x[2] + 1) < TOL,
                 gap=lambda x: np.full(x.shape[1:], -0.01),
                 contact_coordinate=lambda x: np.asarray(x)[:2])


def test_a_flat_push_is_reproduced(pushed_cube):
    solution = solve_hex_vi(pushed_cube, hex_mesh(pushed_cube, 1))
    assert solution.status == "ok"
    assert solution.contact_force == pytest.approx(20.0, rel=1e-12)  # direct-solve round-off
    assert solution.energy == pytest.approx(0.1, rel=1e-12)
    uz = solution.u[solution.elasticity.basis.nodal_dofs[2]]
    assert np.allclose(uz, 0.005 * (1 - solution.elasticity.mesh.p[2]), atol=1e-14)


def test_the_fast_solve_agrees_with_the_reference_solver():
    scene = get_scene("free-boundary-3d")
    fast = solve_hex_vi(scene, hex_mesh(scene, 1), "active-set")
    judge = solve_hex_vi(scene, hex_mesh(scene, 1), "reference")
    # Clarabel stops at a relative gap of about 1e-8
    assert fast.energy == pytest.approx(judge.energy, rel=1e-6)
    assert hex_error(scene, fast) == pytest.approx(hex_error(scene, judge), rel=1e-4)


def test_the_error_against_the_exact_solution_falls():
    rows = hex_sequence("free-boundary-3d", 20000)
    errors = [r.energy_error for r in rows]
    assert [r.ndofs for r in rows] == [300, 1944, 13872]
    # measured 3.20e-3, 3.01e-3, 1.15e-3 (then 5.97e-4 at 104 544 DOFs: slope -0.33, O(h))
    assert errors[2] < 0.5 * errors[1] < 0.5 * errors[0]


def test_a_scene_without_a_grid_of_cubes_is_refused():
    with pytest.raises(ValueError, match="no hexahedral version"):
        hex_mesh(get_scene("paper"))

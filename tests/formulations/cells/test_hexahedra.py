"""Contact on hexahedra (Q1, uniform) through the registered formulations and the
quadrilateral-face contact boundary: a rigid flat pressing a cube up is reproduced exactly, the
active-set solve agrees with Clarabel, and the error against free-boundary-3d's exact solution
falls at O(h)."""

import numpy as np
import pytest

from bench.measure.slope import fit_slope
from bench.sequence.loop import LoopConfig, run_sequence
from bench.truth import truth_for
from formulations import get_formulation, solve
from formulations.cells import family_for
from scenes import Material, Scene, get_scene
from scenes.budget import tensor_mesh

TOL = 1e-10
HEXAHEDRA = family_for("quad", 3)


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


@pytest.mark.parametrize("formulation", ["vi", "nitsche"])
def test_a_flat_push_is_reproduced(pushed_cube, formulation):
    mesh = HEXAHEDRA.starting_mesh(pushed_cube).refined()
    solution = solve(get_formulation(formulation)(pushed_cube, mesh), "active-set")
    assert solution.status == "ok"
    # the VI's nodal constraints and Nitsche's consistent contact hold the push exactly, up to
    # the solve's round-off (the penalty needs a penetration: not exact)
    assert solution.contact_force() == pytest.approx(20.0, rel=1e-9)
    assert solution.energy == pytest.approx(0.1, rel=1e-9)
    uz = solution.u[solution.elasticity.basis.nodal_dofs[2]]
    assert np.allclose(uz, 0.005 * (1 - mesh.p[2]), atol=1e-11)


def test_the_fast_solve_agrees_with_the_reference_solver():
    scene = get_scene("free-boundary-3d")
    mesh = HEXAHEDRA.starting_mesh(scene).refined()
    fast = solve(get_formulation("vi")(scene, mesh), "active-set")
    judge = solve(get_formulation("vi")(scene, mesh), "reference")
    # Clarabel stops at a relative gap of about 1e-8
    assert fast.energy == pytest.approx(judge.energy, rel=1e-7)
    assert fast.contact_force() == pytest.approx(judge.contact_force(), rel=1e-5)


def test_the_error_against_the_exact_solution_falls_at_order_h():
    scene = get_scene("free-boundary-3d")
    results = list(run_sequence(scene, "vi", "active-set", "averaging",
                                LoopConfig(strategy="uniform", cell="quad", max_dofs=20000),
                                truth=truth_for(scene, None)))
    assert [r.row.ndofs for r in results] == [300, 1944, 13872]
    errors = np.array([r.row.energy_error for r in results])
    # measured 3.16e-3, 2.26e-3, 1.14e-3 (then 5.91e-4 at 104 544 DOFs: the last two levels'
    # slope -0.33, O(h) = N^(-1/3)); the first pair is pre-asymptotic
    assert fit_slope([1944, 13872], errors[1:]).slope == pytest.approx(-1 / 3, abs=0.05)


def test_a_scene_without_a_grid_of_cubes_is_refused():
    with pytest.raises(ValueError, match="no hexahedral version"):
        HEXAHEDRA.starting_mesh(get_scene("paper"))


@pytest.mark.slow
def test_q1_hexahedra_converge_at_order_h_to_1e5_dofs():
    """Uniform Q1 on free-boundary-3d to 104 544 DOFs: the error's slope over the last three
    levels within 0.05 of -1/3 (O(h) in 3D; measured 2.26e-3, 1.14e-3, 5.91e-4 from 1 944 DOFs:
    -0.33), and the active-set solve agreeing with Clarabel in energy at 13 872 DOFs."""
    scene = get_scene("free-boundary-3d")
    results = list(run_sequence(scene, "vi", "active-set", "averaging",
                                LoopConfig(strategy="uniform", cell="quad", max_dofs=120000),
                                truth=truth_for(scene, None)))
    assert [r.row.ndofs for r in results][-1] == 104544
    tail = results[-3:]
    slope = fit_slope([r.row.ndofs for r in tail], [r.row.energy_error for r in tail]).slope
    assert slope == pytest.approx(-1 / 3, abs=0.05)  # the gate on the rate
    mesh = HEXAHEDRA.starting_mesh(scene).refined(2)
    fast = solve(get_formulation("vi")(scene, mesh), "active-set")
    judge = solve(get_formulation("vi")(scene, mesh), "reference")
    # Clarabel's interior point stops at a relative gap of about 1e-8
    assert fast.energy == pytest.approx(judge.energy, rel=1e-7)

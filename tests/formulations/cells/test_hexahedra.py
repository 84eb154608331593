"""Contact on hexahedra (Q1, uniform and graded with hanging nodes) through the registered
formulations and the quadrilateral-face contact boundary: a rigid flat pressing a cube up is
reproduced exactly, the active-set solve agrees with Clarabel, the free DOFs are counted before
assembly, and the error against free-boundary-3d's exact solution falls at O(h) uniformly and
adaptively."""

import numpy as np
import pytest
from skfem import Basis, ElementHex1, ElementVector

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


def graded(mesh, point, times: int):
    """``mesh`` refined ``times`` times at the leaf nearest ``point``: hanging edges and faces,
    some of them on Gamma_C."""
    for _ in range(times):
        distance = np.linalg.norm(mesh.p[:, mesh.t].mean(axis=1) - np.reshape(point, (3, 1)),
                                  axis=0)
        mesh = mesh.refined([np.argmin(distance)])
    return mesh


@pytest.mark.parametrize("formulation", ["vi", "nitsche"])
def test_a_flat_push_is_reproduced_on_a_graded_mesh(pushed_cube, formulation):
    """The trilinear push is in the constrained space: hanging nodes on Gamma_C and inside
    change nothing, and the force and energy stay exact to the solve's round-off."""
    mesh = graded(HEXAHEDRA.starting_mesh(pushed_cube), (0.3, 0.2, -1.0), 3)
    assert mesh.hierarchy.hanging_faces()[0].size > 0
    solution = solve(get_formulation(formulation)(pushed_cube, mesh), "active-set")
    assert solution.status == "ok"
    assert solution.contact_force() == pytest.approx(20.0, rel=1e-9)
    assert solution.energy == pytest.approx(0.1, rel=1e-9)
    uz = solution.u[solution.elasticity.basis.nodal_dofs[2]]
    assert np.allclose(uz, 0.005 * (1 - mesh.p[2]), atol=1e-11)  # hanging nodes too


def test_a_constrained_field_is_continuous_across_hanging_edges_and_faces():
    """For any conforming coefficients, P u at every vertex that lies on a leaf's closure
    equals that leaf's trilinear field there (the leaves are axis-aligned boxes here, so the
    field is evaluated from their corners alone, independently of the constraint code)."""
    scene = get_scene("free-boundary-3d")
    mesh = graded(HEXAHEDRA.starting_mesh(scene), (0.1, 0.1, 0.0), 3)
    basis = Basis(mesh, ElementVector(ElementHex1()))
    P = HEXAHEDRA.constraint(basis)
    u = (P @ np.random.default_rng(1).standard_normal(P.shape[1]))[basis.nodal_dofs[0]]
    low, high = mesh.p[:, mesh.t].min(axis=1), mesh.p[:, mesh.t].max(axis=1)  # (3, cells)
    t = (mesh.p[:, None, :] - low[:, :, None]) / (high - low)[:, :, None]  # (3, cells, verts)
    inside = ((t > -1e-12) & (t < 1 + 1e-12)).all(axis=0)
    corners = (mesh.p[:, mesh.t] - low[:, None]) / (high - low)[:, None]  # (3, 8, cells)
    weights = np.prod(np.where(np.round(corners)[..., None] == 1, t[:, None],
                               1 - t[:, None]), axis=0)  # (8, cells, verts)
    field = np.einsum("kc,kcv->cv", u[mesh.t], weights)
    assert inside.sum() > 8 * mesh.t.shape[1]  # hanging vertices lie on coarse leaves
    assert np.allclose(field[inside], np.broadcast_to(u, field.shape)[inside], atol=1e-12)


def test_free_dofs_are_counted_before_assembly_with_hanging_nodes():
    scene = get_scene("free-boundary-3d")
    mesh = graded(HEXAHEDRA.starting_mesh(scene), (0.1, 0.1, 0.0), 3)
    problem = get_formulation("vi")(scene, mesh)
    assert HEXAHEDRA.count_free_dofs(scene, mesh, 1) == problem.elasticity.free.size


def test_the_fast_solve_agrees_with_the_reference_solver_with_hanging_nodes():
    scene = get_scene("free-boundary-3d")
    mesh = graded(HEXAHEDRA.starting_mesh(scene), (0.1, 0.1, 0.0), 3)
    fast = solve(get_formulation("vi")(scene, mesh), "active-set")
    judge = solve(get_formulation("vi")(scene, mesh), "reference")
    # Clarabel stops at a relative gap of about 1e-8
    assert fast.energy == pytest.approx(judge.energy, rel=1e-7)


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

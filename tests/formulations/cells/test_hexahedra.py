"""Contact on hexahedra (Q1, uniform and graded with hanging nodes) through the registered
formulations and the quadrilateral-face contact boundary: a rigid flat pressing a cube up is
reproduced exactly, the active-set solve agrees with Clarabel, the free DOFs are counted before
assembly, and the error against free-boundary-3d's exact solution falls at O(h) uniformly and
adaptively."""

import dataclasses

import numpy as np
import pytest
from skfem import Basis

from bench.measure.slope import fit_slope
from bench.sequence.loop import LoopConfig, run_sequence
from bench.truth import truth_for
from formulations import get_formulation, solve
from formulations.cells import family_for
from scenes import get_scene

HEXAHEDRA = family_for("quad", 3)


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


@pytest.mark.parametrize("formulation, order", [("vi", 1), ("nitsche", 1), ("vi", 2)])
def test_a_flat_push_is_reproduced_on_a_graded_mesh(pushed_cube, formulation, order):
    """The trilinear push is in the constrained space: hanging nodes on Gamma_C and inside
    change nothing, and the force and energy stay exact to the solve's round-off."""
    mesh = graded(HEXAHEDRA.starting_mesh(pushed_cube), (0.3, 0.2, -1.0), 3)
    assert mesh.hierarchy.hanging_faces()[0].size > 0
    solution = solve(get_formulation(formulation)(pushed_cube, mesh, order=order),
                     "active-set")
    assert solution.status == "ok"
    assert solution.contact_force() == pytest.approx(20.0, rel=1e-9)
    assert solution.energy == pytest.approx(0.1, rel=1e-9)
    uz = solution.u[solution.elasticity.basis.nodal_dofs[2]]
    assert np.allclose(uz, 0.005 * (1 - mesh.p[2]), atol=1e-11)  # hanging nodes too
    if formulation == "vi":  # hanging contact nodes take their parents' pressure
        assert np.allclose(solution.details.nodal_pressure, 5.0, rtol=1e-9)


def test_hanging_contact_nodes_are_no_constraints_of_their_own(pushed_cube):
    """On a graded Gamma_C the VI constrains the conforming nodes only: the nodal
    prolongation's rows sum to one (it interpolates), the kept nodes' conforming masses sum
    to Gamma_C's area, and the constraints are fewer than the nodes."""
    from functools import partial

    from formulations.contact import contact_trace
    from formulations.contact.boundary import conforming_nodes
    from formulations.elasticity import assemble_elasticity

    mesh = graded(HEXAHEDRA.starting_mesh(pushed_cube), (0.3, 0.2, -1.0), 3)
    for order in (1, 2):
        elasticity = assemble_elasticity(pushed_cube, mesh, order)
        trace = contact_trace(pushed_cube, mesh)
        nodes = trace.nodes(order)
        kept = conforming_nodes(elasticity, partial(trace.node_rows, elasticity, nodes),
                                nodes.weight.size)
        assert 0 < kept.kept.size < nodes.weight.size
        assert np.allclose(np.asarray(kept.S.sum(axis=1)).ravel(), 1.0, atol=1e-14)
        assert kept.weights(nodes.weight).sum() == pytest.approx(4.0, rel=1e-12)


def lagrange_1d(nodes: np.ndarray, t: np.ndarray) -> np.ndarray:
    """The Lagrange polynomials of ``nodes`` at t (..., ): shape (len(nodes), ...)."""
    return np.array([np.prod([(t - b) / (a - b) for b in nodes if b != a], axis=0)
                     for a in nodes])


@pytest.mark.parametrize("order", [1, 2])
def test_a_constrained_field_is_continuous_across_hanging_edges_and_faces(order):
    """For any conforming coefficients, P u at every Lagrange node that lies on a leaf's
    closure equals that leaf's Q_order field there. The leaves are axis-aligned boxes, so the
    field is the tensor Lagrange interpolant of the leaf's nodal values, found from the nodes'
    coordinates alone, independently of the constraint code and of scikit-fem's basis."""
    scene = get_scene("free-boundary-3d")
    mesh = graded(HEXAHEDRA.starting_mesh(scene), (0.1, 0.1, 0.0), 3)
    basis = Basis(mesh, HEXAHEDRA.elements[order](), intorder=1)
    P = HEXAHEDRA.constraint(basis)
    u = P @ np.random.default_rng(1).standard_normal(P.shape[1])
    x = basis.doflocs  # (3, N)
    low, high = mesh.p[:, mesh.t].min(axis=1), mesh.p[:, mesh.t].max(axis=1)  # (3, cells)
    t = (x[:, None, :] - low[:, :, None]) / (high - low)[:, :, None]  # (3, cells, N)
    inside = ((t > -1e-12) & (t < 1 + 1e-12)).all(axis=0)
    nodes = np.linspace(0, 1, order + 1)
    own = (x[:, basis.element_dofs] - low[:, None]) / (high - low)[:, None]  # (3, k, cells)
    index = np.rint(own * order).astype(int)  # each own node's place on the tensor grid
    values = np.zeros((order + 1,) * 3 + (mesh.t.shape[1],))
    values[index[0], index[1], index[2], np.arange(mesh.t.shape[1])] = u[basis.element_dofs]
    lx, ly, lz = (lagrange_1d(nodes, t[k]) for k in range(3))  # (order + 1, cells, N)
    field = np.einsum("ijkc,icn,jcn,kcn->cn", values, lx, ly, lz)
    assert inside.sum() > basis.element_dofs.size  # hanging nodes lie on coarse leaves
    assert np.allclose(field[inside], np.broadcast_to(u, field.shape)[inside], atol=1e-12)


def test_free_dofs_are_counted_before_assembly_with_hanging_nodes(pushed_cube):
    mesh = graded(HEXAHEDRA.starting_mesh(pushed_cube), (0.1, 0.1, 0.0), 3)
    for order in (1, 2):
        problem = get_formulation("vi")(pushed_cube, mesh, order=order)
        assert HEXAHEDRA.count_free_dofs(pushed_cube, mesh, order) == problem.elasticity.free.size


@pytest.mark.parametrize("order", [1, 2])
def test_the_fast_solve_agrees_with_the_reference_solver_with_hanging_nodes(pushed_cube, order):
    """A paraboloid pressed into the graded bottom (contact on part of it, hanging nodes at
    its edge): the active set and Clarabel find the same energy."""
    curved = dataclasses.replace(
        pushed_cube, gap=lambda x: -0.01 + 0.02 * (x[0] ** 2 + x[1] ** 2))
    mesh = graded(HEXAHEDRA.starting_mesh(curved), (0.3, 0.2, -1.0), 3)
    fast = solve(get_formulation("vi")(curved, mesh, order=order), "active-set")
    judge = solve(get_formulation("vi")(curved, mesh, order=order), "reference")
    assert 0 < fast.contact_force() and fast.status == judge.status == "ok"
    # the active set solved it itself: a hanging node's row, a combination of its parents',
    # left its multipliers without a unique answer and sent it to Clarabel's fallback
    assert fast.backend != "clarabel"
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
@pytest.mark.parametrize("strategy, max_dofs, last", [("uniform", 120000, 104544),
                                                      ("adaptive", 100000, 96447)])
def test_q1_hexahedra_converge_at_order_h_to_1e5_dofs(strategy, max_dofs, last):
    """Q1 on free-boundary-3d to about 1e5 DOFs: the error's slope over the last three levels
    within 0.05 of -1/3 (O(h) in 3D, N^(-1/3) uniformly and adaptively: the solution is
    smooth enough that grading gains nothing in rate). Measured: uniform 2.26e-3, 1.14e-3,
    5.91e-4 from 1 944 DOFs (-0.33); adaptive 8.12e-4, 6.19e-4, 4.73e-4 from 20 511 DOFs
    (-0.35)."""
    scene = get_scene("free-boundary-3d")
    results = list(run_sequence(scene, "vi", "active-set", "averaging",
                                LoopConfig(strategy=strategy, cell="quad", max_dofs=max_dofs),
                                truth=truth_for(scene, None)))
    assert results[-1].row.ndofs == last
    assert all(r.row.status == "ok" for r in results)
    tail = results[-3:]
    slope = fit_slope([r.row.ndofs for r in tail], [r.row.energy_error for r in tail]).slope
    assert slope == pytest.approx(-1 / 3, abs=0.05)  # O(h), with 0.05 for the fit's spread


@pytest.mark.slow
def test_the_fast_solve_agrees_with_the_reference_solver_at_1e4_dofs():
    scene = get_scene("free-boundary-3d")
    mesh = HEXAHEDRA.starting_mesh(scene).refined(2)
    fast = solve(get_formulation("vi")(scene, mesh), "active-set")
    judge = solve(get_formulation("vi")(scene, mesh), "reference")
    # Clarabel's interior point stops at a relative gap of about 1e-8
    assert fast.energy == pytest.approx(judge.energy, rel=1e-7)

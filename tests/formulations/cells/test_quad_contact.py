"""Contact on quadrilaterals (Q1, Q2, hanging nodes included) through the registered
formulations, the VI and the seed's mixed method with lambda_H one and two levels coarser
(the multipliers piecewise constant, as in the seed): a rigid flat pressing the body up is
reproduced exactly, and the fast active-set solve agrees with Clarabel."""

import numpy as np
import pytest

from conftest import square_scene
from formulations import get_formulation, solve
from formulations.cells import family_for
from scenes import get_scene
from scenes.quad_hierarchy import QuadHierarchy, coarse_edges


def hierarchy_with_hanging_nodes() -> QuadHierarchy:
    return QuadHierarchy.from_tensor(np.linspace(-1, 1, 5), np.linspace(-1, 1, 5)) \
        .refined([0, 5]).refined([1])


# the seed's methods: formulation and options
METHODS = {"vi": ("vi", {}), "mixed": ("mixed", {"multiplier_degree": 0}),
           "mixed-two-up": ("mixed", {"multiplier_degree": 0, "h_over_H": 0.25})}


def solve_on(method: str, scene, hierarchy: QuadHierarchy, order: int,
             solver: str = "active-set"):
    name, options = METHODS[method]
    return solve(get_formulation(name)(scene, hierarchy.mesh(), order=order, **options), solver)


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("order", [1, 2])
def test_a_flat_push_is_reproduced(compression_scene, order, method):
    """u = (0, delta (1 - y) / 2), pressure E delta / 2 on all of Gamma_C (conftest): linear,
    so in Q1 and Q2; energy 1/2 (E delta^2 / 4) |Omega| = 0.05, force 10."""
    solution = solve_on(method, compression_scene, hierarchy_with_hanging_nodes(), order)
    assert solution.status == "ok"
    assert solution.energy == pytest.approx(0.05, rel=1e-12)  # round-off of a direct solve
    assert solution.contact_force() == pytest.approx(10.0, rel=1e-12)
    basis = solution.elasticity.basis
    uy = solution.u[basis.nodal_dofs[1]]
    assert np.allclose(uy, 0.005 * (1 - basis.mesh.p[1]), atol=1e-14)


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("order", [1, 2])
def test_the_fast_solve_agrees_with_the_reference_solver(order, method):
    scene = get_scene("paper")
    hierarchy = QuadHierarchy.from_tensor(np.linspace(-1, 1, 9), np.linspace(-1, 1, 9))
    hierarchy = hierarchy.refined(np.arange(8))  # the bottom row: hanging nodes above it
    assert hierarchy.hanging()[0].size > 0
    fast = solve_on(method, scene, hierarchy, order)
    judge = solve_on(method, scene, hierarchy, order, solver="reference")
    # Clarabel's interior point stops at a relative gap of about 1e-8
    assert fast.energy == pytest.approx(judge.energy, rel=1e-7)
    assert fast.contact_force() == pytest.approx(judge.contact_force(), rel=1e-6)


def test_an_empty_contact_zone_is_a_free_solve(free_scene):
    hierarchy = QuadHierarchy.from_tensor(np.linspace(-1, 1, 5), np.linspace(-1, 1, 5))
    solution = solve_on("vi", free_scene, hierarchy, 1)
    assert solution.status == "ok" and solution.contact_force() == 0.0
    assert solution.energy < 0  # a body force with nothing in the way: E(u) = -F'u / 2


def test_a_scene_without_contact_rows_is_not_confused_with_one(compression_scene):
    lifted = square_scene(lambda x: np.full(x.shape[1:], 1.0))
    assert solve_on("vi", lifted, hierarchy_with_hanging_nodes(), 1).contact_force() == 0.0


def test_the_multiplier_mesh_is_a_coarser_level_of_the_hierarchy():
    """On a uniform mesh of 8 x 8 leaves, the bottom edge's 8 leaf edges form 4 coarse edges
    one level up (h/H = 1/2) and 2 two levels up (h/H = 1/4), each of consecutive edges."""
    hierarchy = QuadHierarchy.from_tensor(np.linspace(-1, 1, 3), np.linspace(-1, 1, 3))
    hierarchy = hierarchy.refined().refined()
    mesh = hierarchy.mesh()
    bottom = mesh.boundary_facets()[np.isclose(
        mesh.p[1, mesh.facets[:, mesh.boundary_facets()]].mean(axis=0), -1.0)]
    order = np.argsort(mesh.p[0, mesh.facets[:, bottom]].mean(axis=0))
    normal = np.tile([[0.0], [-1.0]], bottom.size)
    for up, size in ((1, 2), (2, 4)):
        group = coarse_edges(hierarchy, mesh.f2t[0, bottom], normal, up)[order]
        assert np.array_equal(group, np.repeat(group[::size], size))
        assert np.unique(group).size == 8 // size


def test_the_inf_sup_constant_levels_off_for_h_over_H_at_most_one_half():
    """beta_h of the mixed method on uniform Q1 hierarchies of paper: with lambda_H on the
    leaves' own edges (h/H = 1) it halves with h (measured 0.46 .. 0.027); one or two levels
    coarser (h/H = 1/2, 1/4) it levels off (measured 0.60 and 0.70 at 4096 cells)."""
    from formulations.diagnostics import inf_sup_constant

    scene = get_scene("paper")
    hierarchy = QuadHierarchy.from_tensor(np.linspace(-1, 1, 5), np.linspace(-1, 1, 5))
    beta = {up: [] for up in (0, 1, 2)}
    for _ in range(5):
        for up in beta:
            mixed = get_formulation("mixed")(scene, hierarchy.mesh(), h_over_H=0.5**up,
                                             multiplier_degree=0)
            beta[up].append(inf_sup_constant(mixed))
        hierarchy = hierarchy.refined()
    same = np.array(beta[0])
    assert np.allclose(same[2:] / same[1:-1], 0.5, atol=0.03)  # beta_h ~ h
    for up in (1, 2):
        levels = np.array(beta[up])
        assert levels[-1] > 0.5  # bounded below ...
        assert abs(levels[-1] / levels[-2] - 1) < 0.03  # ... and levelled off (within 1 %)


def test_multiplier_segments_are_runs_where_a_coarse_leaf_meets_refined_ones():
    """Two levels up from the leaves of a graded bottom edge: a leaf that cannot go the whole
    way up keeps its root edge, which holds the refined leaves' groups too; the segments
    must still be runs along Gamma_C, one per multiplier (a nested group once gave the
    mixed method more segment breaks than rows)."""
    scene = get_scene("paper")
    hierarchy = QuadHierarchy.from_tensor(np.linspace(-1, 1, 3), np.linspace(-1, 1, 3))
    mesh = hierarchy.mesh()
    # the bottom-left root cell to level 1, its corner to level 2, then the level-2 cell on
    # [-0.75, -0.5] to level 3: along y = -1, levels 2, 3, 3, 1 under one root edge
    for centre in ((-0.5, -0.5), (-0.75, -0.75), (-0.625, -0.875)):
        centroids = mesh.p[:, mesh.t].mean(axis=1)
        cell = np.argmin(np.linalg.norm(centroids - np.array(centre)[:, None], axis=0))
        mesh = mesh.hierarchy.refined([cell]).mesh()
    family = family_for("quad", 2)
    trace = get_formulation("mixed")(scene, mesh, h_over_H=0.25).trace
    segment = family.multiplier_groups(mesh, trace, 0.25)
    runs = np.flatnonzero(np.diff(np.r_[-1, segment]))
    assert np.all(np.diff(segment) >= 0) and runs.size == np.unique(segment).size
    mixed = get_formulation("mixed")(scene, mesh, h_over_H=0.25)
    assert mixed.row_coordinate.size == mixed.qp.m

"""Hierarchical quadrilateral meshes: children tile their parent, the mesh stays 1-irregular
under repeated local refinement, uniform refinement leaves no hanging node, and the starting
grid obeys the budget."""

import numpy as np
import pytest

from scenes import SceneError
from scenes.budget import dof_budget
from scenes.quad_hierarchy import QuadHierarchy, cell_edges, edge_keys


def areas(p: np.ndarray, cells: np.ndarray) -> np.ndarray:
    """Areas of quadrilaterals (shoelace), positive when counter-clockwise."""
    x, y = p[0, cells], p[1, cells]
    return 0.5 * (x * np.roll(y, -1, axis=0) - np.roll(x, -1, axis=0) * y).sum(axis=0)


def towards(hierarchy: QuadHierarchy, point, times: int) -> QuadHierarchy:
    """Refine the leaf nearest ``point`` ``times`` times (a corner singularity's grading)."""
    for _ in range(times):
        centres = hierarchy.p[:, hierarchy.cells[:, hierarchy.leaves]].mean(axis=1)
        nearest = np.argmin(np.linalg.norm(centres - np.reshape(point, (2, 1)), axis=0))
        hierarchy = hierarchy.refined([nearest])
    return hierarchy


@pytest.fixture
def graded():
    return towards(QuadHierarchy.from_tensor(np.linspace(-1, 1, 5), np.linspace(-1, 1, 3)),
                   (0.3, -0.2), 5)


def test_uniform_refinement_quarters_every_cell_and_hangs_nothing():
    root = QuadHierarchy.from_tensor(np.linspace(0, 2, 4), np.linspace(0, 1, 3))
    fine = root.refined().refined()
    assert fine.leaves.size == 16 * 6
    assert fine.hanging()[0].size == 0
    assert np.allclose(areas(fine.p, fine.cells[:, fine.leaves]), 2.0 / 96, rtol=1e-14)


def test_children_tile_their_parent_counter_clockwise(graded):
    parents = np.flatnonzero(graded.first_child >= 0)
    children = graded.first_child[parents][:, None] + np.arange(4)
    assert np.all(graded.parent[children] == parents[:, None])
    assert np.all(graded.level[children] == graded.level[parents][:, None] + 1)
    child_area = areas(graded.p, graded.cells[:, children.ravel()]).reshape(-1, 4)
    assert np.all(child_area > 0)
    assert np.allclose(child_area.sum(axis=1), areas(graded.p, graded.cells[:, parents]),
                       rtol=1e-13)
    assert np.isclose(areas(graded.p, graded.cells[:, graded.leaves]).sum(), 4.0, rtol=1e-13)


def test_local_refinement_keeps_one_hanging_node_per_edge(graded):
    """1-irregular, checked from the leaves alone: every leaf edge holds at most one vertex
    of another leaf in its interior, and that one at its midpoint."""
    leaves = graded.cells[:, graded.leaves]
    used = np.unique(leaves)
    a, b = cell_edges(leaves)
    pa, pb = graded.p[:, a.ravel()], graded.p[:, b.ravel()]
    q = graded.p[:, used]
    d = pb - pa
    s = ((q[:, :, None] - pa[:, None, :]) * d[:, None, :]).sum(axis=0) / (d**2).sum(axis=0)
    off = np.linalg.norm(q[:, :, None] - pa[:, None, :] - s[None] * d[:, None, :], axis=0)
    inside = (off < 1e-12) & (s > 1e-12) & (s < 1 - 1e-12)
    assert inside.sum(axis=0).max() == 1 and np.allclose(s[inside], 0.5)
    assert inside.sum() == graded.hanging()[0].size > 10
    assert graded.level[graded.leaves].max() >= 5


def test_a_hanging_node_is_the_midpoint_of_its_coarse_edge(graded):
    node, a, b = graded.hanging()
    assert np.allclose(graded.p[:, node], 0.5 * (graded.p[:, a] + graded.p[:, b]), atol=1e-15)
    assert np.array_equal(graded.midpoints(edge_keys(a, b)), node)


def test_the_starting_grid_obeys_the_budget():
    with dof_budget(300), pytest.raises(SceneError, match="more than max_dofs=300"):
        QuadHierarchy.from_tensor(np.linspace(0, 1, 2001), np.linspace(0, 1, 2001))

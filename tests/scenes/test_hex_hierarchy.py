"""Hierarchical hexahedral meshes: children tile their parent with positive volume, repeated
local refinement keeps every leaf edge and face 1-irregular (checked from the leaves'
geometry alone), the body's boundary is the box's, and uniform refinement hangs nothing."""

import numpy as np
import pytest
from skfem import Basis, ElementHex1

from scenes import SceneError
from scenes.budget import dof_budget
from scenes.hex_hierarchy import EDGES, FACES, LATTICE_EDGE, HexHierarchy


def towards(hierarchy: HexHierarchy, point, times: int) -> HexHierarchy:
    """Refine the leaf nearest ``point`` ``times`` times (a point singularity's grading)."""
    for _ in range(times):
        centres = hierarchy.p[:, hierarchy.cells[:, hierarchy.leaves]].mean(axis=1)
        nearest = np.argmin(np.linalg.norm(centres - np.reshape(point, (3, 1)), axis=0))
        hierarchy = hierarchy.refined([nearest])
    return hierarchy


@pytest.fixture(scope="module")
def graded():
    root = HexHierarchy.from_tensor(np.linspace(-1, 1, 5), np.linspace(0, 1, 3),
                                    np.linspace(0, 2, 5))
    return towards(root, (0.3, 0.2, 0.7), 4)


def hanging_midpoints(hierarchy: HexHierarchy) -> np.ndarray:
    """The midpoints of leaves' edges that are split (each once)."""
    lattice = hierarchy.lattice(hierarchy.leaves)[LATTICE_EDGE >= 0]
    return np.unique(lattice[lattice >= 0])


def volumes(mesh) -> np.ndarray:
    return Basis(mesh, ElementHex1(), intorder=2).dx.sum(axis=1)


def test_uniform_refinement_splits_every_cell_in_eight_and_hangs_nothing():
    root = HexHierarchy.from_tensor(*[np.linspace(0, 1, 3)] * 3)
    fine = root.refined().refined()
    assert fine.leaves.size == 8 * 8 * 8
    assert hanging_midpoints(fine).size == 0 and fine.hanging_faces()[0].size == 0
    # every cell of a uniform grid of 8^3 cubes on the unit cube: 1/512 each
    assert np.allclose(volumes(fine.mesh()), 1 / 512, rtol=1e-13)


def test_one_split_cell_hangs_its_shared_edges_and_faces():
    """A corner cube of a 4^3 grid, split: its 3 inner faces and the 9 edges it shares with a
    neighbour hang (the 3 edges at the box's corner belong to it alone); the body's boundary
    loses 3 squares to 12 quarters."""
    root = HexHierarchy.from_tensor(*[np.linspace(0, 1, 5)] * 3)
    corner = np.argmin(root.p[:, root.cells].sum(axis=0).sum(axis=0))
    split = root.refined([corner])
    assert split.hanging_faces()[0].size == 3
    assert hanging_midpoints(split).size == 9
    assert split.mesh().boundary_facets().size == 6 * 16 - 3 + 12


def test_children_tile_their_parent(graded):
    parents = np.flatnonzero(graded.first_child >= 0)
    children = graded.first_child[parents][:, None] + np.arange(8)
    assert np.all(graded.parent[children] == parents[:, None])
    assert np.all(graded.level[children] == graded.level[parents][:, None] + 1)
    mesh = graded.mesh()
    assert np.all(volumes(mesh) > 0)
    # the leaves fill the box (-1, 1) x (0, 1) x (0, 2) of volume 4
    assert volumes(mesh).sum() == pytest.approx(4.0, rel=1e-13)


def test_local_refinement_keeps_edges_and_faces_one_irregular(graded):
    """From the leaves' geometry alone: the only mesh vertex a leaf's edge may hold inside is
    its midpoint, and the only one inside a leaf's face its centre (a neighbour one level
    finer); a vertex at a quarter point would be a neighbour two levels finer."""
    leaves, p = graded.cells[:, graded.leaves], graded.p
    keys = {tuple(np.round(v, 12)) for v in p[:, np.unique(leaves)].T}
    quarters = (0.25, 0.75)
    for i, j in EDGES:
        a, b = p[:, leaves[i]], p[:, leaves[j]]
        for s in quarters:
            assert not _hits(keys, a + s * (b - a)).any()
    for c0, c1, _, c3 in FACES:
        a, u, v = p[:, leaves[c0]], p[:, leaves[c1]] - p[:, leaves[c0]], \
            p[:, leaves[c3]] - p[:, leaves[c0]]
        for s, t in [(s, t) for s in (0.25, 0.5, 0.75) for t in (0.25, 0.5, 0.75)]:
            if (s, t) != (0.5, 0.5):
                assert not _hits(keys, a + s * u + t * v).any()
    levels = graded.level[graded.leaves]
    assert levels.max() == 4 and levels.min() == 0  # graded: a coarse leaf stays


def _hits(keys: set, points: np.ndarray) -> np.ndarray:
    """Which points coincide with a vertex (rounded to 1e-12, as ``keys`` are)."""
    return np.array([tuple(np.round(x, 12)) in keys for x in points.T])


def test_the_body_boundary_is_the_box_surface(graded):
    mesh = graded.mesh()
    facets = mesh.boundary_facets()
    x = mesh.p[:, mesh.facets[:, facets]]
    on_box = ((np.abs(np.abs(x[0]) - 1) < 1e-12).all(axis=0)
              | (np.abs(x[1] - 0.5) > 0.5 - 1e-12).all(axis=0)
              | (np.abs(x[2] - 1) > 1 - 1e-12).all(axis=0))
    assert on_box.all()
    # the faces cover the box's surface, 2 (2 + 4 + 2) = 16
    lengths = np.ptp(x, axis=1)
    area = np.sort(lengths, axis=0)[1:].prod(axis=0).sum()
    assert area == pytest.approx(16.0, rel=1e-13)


def test_a_grid_over_budget_is_refused_before_it_is_built():
    with dof_budget(300), pytest.raises(SceneError, match="max_dofs=300"):
        HexHierarchy.from_tensor(*[np.linspace(0, 1, 41)] * 3)


def test_faces_are_scikit_fems_in_cyclic_order():
    from skfem.refdom import RefHex

    assert [sorted(f) for f in FACES] == [sorted(f) for f in RefHex.facets]
    assert list(EDGES) == [tuple(e) for e in RefHex.edges]

"""The topology and refinement of scenes.topology are scikit-fem's own arrays and meshes, bit
for bit (scikit-fem builds them independently, by np.unique on vertex pairs)."""

import numpy as np
import pytest
from skfem import MeshTri

from scenes import get_scene
from scenes.topology import ensure_topology, refined


def skfem_copy(mesh: MeshTri) -> MeshTri:
    return MeshTri(mesh.p.copy(), mesh.t.copy())  # no cached topology


@pytest.mark.parametrize("name", ["paper", "hertz", "graded", "free-boundary"])
def test_topology_and_adaptive_refinement_equal_scikit_fem(name):
    rng = np.random.default_rng(7)
    theirs = skfem_copy(get_scene(name).mesh)
    mine = skfem_copy(theirs)
    for _ in range(5):
        ensure_topology(mine)
        for attribute in ("facets", "t2f", "f2t"):
            assert np.array_equal(getattr(mine, attribute), getattr(theirs, attribute))
        marked = np.flatnonzero(rng.random(theirs.t.shape[1]) < 0.2)
        theirs, mine = theirs.refined(marked), refined(mine, marked)
        assert np.array_equal(mine.p, theirs.p) and np.array_equal(mine.t, theirs.t)


def test_uniform_refinement_and_clockwise_triangles():
    paper = get_scene("paper").mesh
    clockwise = MeshTri(paper.p, paper.t[[0, 2, 1]], sort_t=False)
    for mesh in (paper, clockwise):
        theirs = skfem_copy(mesh).refined()
        mine = refined(skfem_copy(mesh))
        assert np.array_equal(mine.t, theirs.t) and np.array_equal(mine.facets, theirs.facets)
    topology = ensure_topology(MeshTri(clockwise.p, clockwise.t, sort_t=False))
    assert np.array_equal(topology.t2f, MeshTri(clockwise.p, clockwise.t, sort_t=False).t2f)


def test_meshes_with_their_topology_are_left_alone():
    mesh = skfem_copy(get_scene("paper").mesh)
    facets = mesh.facets  # scikit-fem's, cached
    assert ensure_topology(mesh).facets is facets

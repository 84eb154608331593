"""The refined load rule (formulations/cells/load.py): the same rule whatever order an element lists
its vertices in."""

import numpy as np
from skfem import Basis, ElementTetP1, ElementTetP2, ElementVector, MeshTet

from formulations.cells.load import body_load, refined_rule
from scenes import get_scene


def shuffled(mesh: MeshTet, seed: int = 0) -> MeshTet:
    """The same tetrahedra, each listing its vertices in a random order."""
    rng = np.random.default_rng(seed)
    order = np.argsort(rng.random(mesh.t.shape), axis=0)
    return MeshTet(mesh.p, np.take_along_axis(mesh.t, order, axis=0))


def test_the_load_does_not_depend_on_the_vertex_order_of_the_tetrahedra():
    # free-boundary-3d's f jumps across |x| = a, so its rough elements take the refined rule,
    # whose red refinement cuts the octahedron along a diagonal chosen by vertex order. Listing
    # the vertices otherwise must give the same sub-tetrahedra, so the loads agree to round-off
    # (1e-12 of the largest entry; measured ~1e-15). A diagonal taken from the local order
    # differs by ~3e-3 of it.
    scene = get_scene("free-boundary-3d")
    mesh = scene.mesh.refined(1)
    other = shuffled(mesh)
    for element in (ElementTetP1(), ElementTetP2()):
        mine = body_load(scene.body_force, Basis(mesh, ElementVector(element)))
        theirs = body_load(scene.body_force, Basis(other, ElementVector(element)))
        if isinstance(element, ElementTetP1):  # vertex DOFs: the same numbering on both
            assert np.abs(mine - theirs).max() <= 1e-12 * np.abs(mine).max()
        assert abs(mine.sum() - theirs.sum()) <= 1e-12 * np.abs(mine).sum()
    rough = refined_rule(scene.body_force, Basis(mesh, ElementVector(ElementTetP1())))[0]
    assert rough.size > 0  # the refined rule was exercised
    assert np.array_equal(
        rough, refined_rule(scene.body_force, Basis(other, ElementVector(ElementTetP1())))[0])

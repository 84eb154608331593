"""Errors between solutions on different tetrahedral meshes: point location, red children, the
nested transfer and agreement with the exact error."""

import numpy as np
import pytest
from skfem import MeshTet

from bench.measure.discretisation_error import exact_errors
from bench.measure.fields import GradientField
from bench.measure.locator_3d import TetLocator
from bench.measure.nonnested import _measure, _tet_children, energy_difference
from formulations import get_formulation, solve
from scenes import get_scene


def solved(scene, mesh, order=1):
    sol = solve(get_formulation("vi")(scene, mesh, order=order), "active-set")
    assert sol.status == "ok", sol.reason
    return sol


def test_eight_red_children_tile_their_parent():
    corners = np.random.default_rng(0).random((3, 4, 6))
    children = _tet_children(corners)
    volumes = _measure(children).reshape(8, 6)
    # each child is an eighth; 1e-12 relative is round-off on volumes of order 1e-2
    np.testing.assert_allclose(volumes, np.broadcast_to(_measure(corners) / 8, (8, 6)),
                               rtol=1e-12)


def test_every_point_is_found_in_a_tetrahedron_that_contains_it():
    mesh = MeshTet.init_tensor(*(np.linspace(-1, 1, 5),) * 3).refined(1)
    locator = TetLocator.from_mesh(mesh)
    x = np.random.default_rng(1).uniform(-1, 1, (3, 2000))
    cells = locator.find(x)
    bary = locator.barycentric(x, cells)
    assert bary.min() > -1e-12  # the point lies in the cell, up to round-off
    with pytest.raises(ValueError, match="lies outside the mesh"):
        locator.find(np.array([[0.0], [0.0], [1.5]]))


def _interpolated_on(coarse, fine_sol):
    """The coarse P1 solution as a P1 vector on the fine mesh (nested: exact)."""
    mesh, fine = coarse.elasticity.mesh, fine_sol.elasticity
    locator = TetLocator.from_mesh(mesh)
    cells = locator.find(fine.mesh.p)
    bary = locator.barycentric(fine.mesh.p, cells)
    u = np.zeros(fine.basis.N)
    for c in range(3):
        nodal = coarse.u[coarse.elasticity.basis.nodal_dofs[c]]
        u[fine.basis.nodal_dofs[c]] = np.einsum("kn,kn->n", bary, nodal[mesh.t[:, cells]])
    return u


def test_transfer_is_exact_on_nested_tetrahedral_meshes():
    # a coarse P1 field is a P1 field of the red refinement: the fine stiffness matrix gives its
    # distance to the fine solution independently of the cell integration
    scene = get_scene("free-boundary-3d")
    coarse, fine = solved(scene, scene.mesh.refined(1)), solved(scene, scene.mesh.refined(2))
    e = fine.u - _interpolated_on(coarse, fine)
    expected = np.sqrt(e @ fine.elasticity.K @ e)
    first = GradientField.from_solution(fine.elasticity.basis, fine.u)
    second = GradientField.from_solution(coarse.elasticity.basis, coarse.u)
    lame = fine.elasticity.lame
    assert energy_difference(first, second, lame) == pytest.approx(expected, rel=1e-10)
    # coarse first: its cells split into red children that need not be the fine mesh's (the
    # inner octahedron has three diagonals), so the fine field is extended across its own
    # faces; measured 0.2 % off here
    assert energy_difference(second, first, lame) == pytest.approx(expected, rel=0.01)


@pytest.mark.slow  # a P2 solve and a non-nested error on 1e5 quadrature points: about 16 s
def test_error_against_a_p2_solution_is_the_exact_error_up_to_its_own():
    scene = get_scene("free-boundary-3d")
    judged, sharper = solved(scene, scene.mesh.refined(1)), solved(scene, scene.mesh.refined(2), 2)
    exact = exact_errors(scene, judged).energy_error
    own = exact_errors(scene, sharper).energy_error
    measured = energy_difference(GradientField.from_solution(judged.elasticity.basis, judged.u),
                                 GradientField.from_solution(sharper.elasticity.basis, sharper.u),
                                 judged.elasticity.lame)
    # ||e_judged - e_sharper|| differs from ||e_judged|| by at most ||e_sharper|| (triangle
    # inequality); measured: 2.766e-3 against 2.761e-3, own error 3.2e-4
    assert abs(measured - exact) <= own

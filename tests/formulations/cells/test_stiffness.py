"""The closed-form P1 and the vectorised P2 stiffness equal scikit-fem's generic assembly of the
same bilinear form (an independent implementation: quadrature on reference elements) to
round-off."""

import numpy as np
import pytest
from skfem import Basis, MeshTri, asm
from skfem.models.elasticity import linear_elasticity

from formulations.cells.p1_stiffness import p1_stiffness
from formulations.cells.p2_stiffness import p2_stiffness
from formulations.elasticity import vector_element
from scenes import get_scene


def meshes():
    paper = get_scene("paper").mesh.refined(2)
    graded = get_scene("graded").mesh  # aspect ratios up to ~130
    clockwise = MeshTri(paper.p, paper.t[[0, 2, 1]])  # negative Jacobians
    jittered = MeshTri(paper.p + 0.02 * np.random.default_rng(1).standard_normal(paper.p.shape)
                       * (np.abs(paper.p) < 1), paper.t)  # interior nodes moved
    return {"paper": paper, "graded": graded, "clockwise": clockwise, "jittered": jittered}


@pytest.mark.parametrize("name", list(meshes()))
@pytest.mark.parametrize("lam, mu", [(1.0, 0.5), (5.3e4, 2.6e4), (1e6, 1.0)])
def test_closed_form_equals_scikit_fem(name, lam, mu):
    mesh = meshes()[name]
    basis = Basis(mesh, vector_element(1))
    mine = p1_stiffness(mesh, lam, mu)
    theirs = asm(linear_elasticity(lam, mu), Basis(mesh, basis.elem, intorder=0)).tocsr()
    # a sum of a few products per entry, in another order: round-off of max |K| (1e-14)
    assert abs(mine - theirs).max() <= 1e-14 * abs(theirs).max()
    # symmetric local matrices; the sparse sum of an entry and of its mirror may add the
    # same element contributions in another order: round-off only
    assert mine.shape == theirs.shape and abs(mine - mine.T).max() <= 1e-15 * abs(mine).max()


@pytest.mark.parametrize("name", list(meshes()))
@pytest.mark.parametrize("lam, mu", [(1.0, 0.5), (5.3e4, 2.6e4), (1e6, 1.0)])
def test_p2_equals_scikit_fem(name, lam, mu):
    mesh = meshes()[name]
    mine = p2_stiffness(mesh, lam, mu)
    # scikit-fem's rule of order 2 is exact for the strain products of P2, as is ours
    theirs = asm(linear_elasticity(lam, mu), Basis(mesh, vector_element(2), intorder=2)).tocsr()
    assert mine.shape == theirs.shape  # same DOF numbering (scikit-fem's)
    # sums of a few dozen products per entry in another order: round-off of max |K|
    # (measured 1.7e-16 .. 4.2e-16)
    assert abs(mine - theirs).max() <= 1e-14 * abs(theirs).max()
    assert abs(mine - mine.T).max() == 0.0  # mirrored blocks are transposes: exactly symmetric


@pytest.mark.parametrize("dim", [2, 3])
def test_barycentric_gradients_are_those_of_scikit_fems_p1_basis(dim):
    """Against the gradients of scikit-fem's P1 basis functions and the sum of its
    quadrature weights (the measure), on a distorted mesh: round-off, 1e-12."""
    from skfem import ElementTetP1, ElementTriP1, MeshTet

    from formulations.cells.p1_stiffness import barycentric_gradients

    mesh_type, element = (MeshTri, ElementTriP1) if dim == 2 else (MeshTet, ElementTetP1)
    mesh = mesh_type.init_tensor(*[np.linspace(0, 1, 3)] * dim)
    rng = np.random.default_rng(4)
    mesh = mesh_type(mesh.p + 0.1 * rng.uniform(-1, 1, mesh.p.shape), mesh.t)
    basis = Basis(mesh, element(), intorder=1)
    g, measure = barycentric_gradients(mesh)
    assert g.shape == (dim + 1, dim, mesh.t.shape[1])
    for i in range(dim + 1):
        np.testing.assert_allclose(g[i], np.asarray(basis.basis[i][0].grad)[:, :, 0],
                                   atol=1e-12)
    np.testing.assert_allclose(measure, basis.dx.sum(axis=1), rtol=1e-12)

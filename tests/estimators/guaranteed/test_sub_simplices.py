"""The refined reference simplex and its lowest-order Raviart-Thomas data
(estimators.guaranteed.sub_simplices)."""

import numpy as np
import pytest
from skfem import (
    Basis,
    BilinearForm,
    ElementTetP0,
    ElementTetRT0,
    ElementTriP0,
    ElementTriRT0,
    MeshTet,
    MeshTri,
    asm,
)
from skfem.helpers import dot
from skfem.refdom import RefTet, RefTri

from estimators.guaranteed.jump_flux import _least_flux
from estimators.guaranteed.sub_simplices import sub_simplices

REFDOM = {2: RefTri, 3: RefTet}
SKFEM = {2: (MeshTri, ElementTriRT0, ElementTriP0), 3: (MeshTet, ElementTetRT0, ElementTetP0)}


@pytest.mark.parametrize("d, levels", [(2, 1), (2, 2), (3, 1), (3, 2)])
def test_every_inner_face_leaves_one_sub_simplex_and_enters_another(d, levels):
    sub = sub_simplices(REFDOM[d], levels)
    n_sub = 2 ** (d * levels)
    boundary = (d + 1) * 2 ** ((d - 1) * levels)  # faces of the reference simplex's facets
    assert sub.corners.shape == (n_sub, d + 1, d)
    assert sub.incidence.shape == (n_sub, (n_sub * (d + 1) - boundary) // 2)
    assert np.array_equal(sub.incidence.sum(axis=0), np.zeros(sub.incidence.shape[1]))
    assert np.array_equal(np.abs(sub.incidence).sum(axis=0), 2 * np.ones(sub.incidence.shape[1]))
    assert (sub.face >= 0).sum() == 2 * sub.incidence.shape[1]


def _skfem_least_norm(d, levels, A, moments):
    """min ||tau||^2 over scikit-fem's RT_0 on the mapped sub-simplices with tau . n = 0 on
    the boundary and int_S div tau_r = moments[S, r]: the same space in another basis."""
    mesh_type, rt, p0 = SKFEM[d]
    sub = sub_simplices(REFDOM[d], levels)
    points = np.einsum("ij,skj->iks", A, sub.corners)                    # (d, d + 1, n_sub)
    flat = points.transpose(0, 2, 1).reshape(d, -1)
    nodes, index = np.unique(np.round(flat, 12), axis=1, return_inverse=True)
    mesh = mesh_type(nodes, index.reshape(-1, d + 1).T)
    # the sub-simplices' order in the mesh: find each centroid's own
    centroids = points.mean(axis=1)
    order = mesh.element_finder()(*centroids)
    flux = Basis(mesh, rt(), intorder=2)
    pressure = Basis(mesh, p0(), quadrature=flux.quadrature)
    M = asm(BilinearForm(lambda u, v, w: dot(u, v)), flux)
    D = asm(BilinearForm(lambda u, q, w: u.div * q), flux, pressure)      # (n_sub, N)
    free = np.setdiff1d(np.arange(flux.N), flux.get_dofs().flatten())
    M, D = M[free][:, free].toarray(), D[:, free].toarray()
    D = D[order][:-1]                                                     # ours: last dropped
    schur = D @ np.linalg.solve(M, D.T)
    m = moments[:-1]
    return float(np.einsum("sr,sr->", m, np.linalg.solve(schur, m)))


@pytest.mark.parametrize("d, levels", [(2, 1), (2, 2), (3, 1), (3, 2)])
def test_the_least_flux_is_scikit_fems_least_rt0_flux(d, levels):
    rng = np.random.default_rng(3)
    A = np.eye(d) + 0.3 * rng.normal(size=(d, d))
    moments = rng.normal(size=(2 ** (d * levels), d))
    moments -= moments.mean(axis=0)
    ours, coefficients = _least_flux(A[None], moments[None], sub_simplices(REFDOM[d], levels))
    # the same minimum in two bases: agreement to round-off (1e-9 relative)
    assert ours[0] == pytest.approx(_skfem_least_norm(d, levels, A, moments), rel=1e-9)
    sub = sub_simplices(REFDOM[d], levels)
    assert np.allclose(sub.incidence @ coefficients[0], moments, atol=1e-10)

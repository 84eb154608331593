"""The vertex-patch equilibration (docs/theory.md, 13.2): the patch layout's shared unknowns (a
DOF on a facet at a patch's vertex is one unknown of that patch, held by one of the facet's two
elements), and on tetrahedra the stress itself."""

import numpy as np
import pytest
from skfem import FacetBasis

from conftest import CUBE_LAME, CUBE_STRAIN, cube_problem, faces_normal
from estimators.guaranteed.equilibration import facet_holders, reconstruct
from estimators.guaranteed.raviart_thomas_tet import ElementTetRTk
from estimators.guaranteed.rt_reference import OPPOSITE_FACET, ReferenceRT
from scenes import get_scene


def locally_refined_mesh():
    mesh = get_scene("hertz").mesh
    for _ in range(3):  # hanging-node-free local refinement: irregular neighbourhoods
        mesh = mesh.refined(np.arange(0, mesh.t.shape[1], 3))
    return mesh


@pytest.mark.parametrize("k", [1, 2, 3])
def test_every_read_holder_holds_the_same_dof_and_vertex_in_the_facets_first_element(k):
    """Checked against the definition entry by entry, not against another fast formula."""
    mesh = locally_refined_mesh()
    dofs = ReferenceRT.build(mesh, k, 2 * k + 2).element_dofs           # (n_rt, n_el)
    n_rt, n_el = dofs.shape
    holder = facet_holders(mesh, dofs, k)
    pair = np.repeat(np.arange(3 * n_el)[:, None], n_rt, axis=1)
    slot = np.repeat(np.arange(n_rt)[None, :], 3 * n_el, axis=0)
    facet_slot = slot < 3 * (k + 1)
    local_facet = np.where(facet_slot, slot // (k + 1), -1)
    read = local_facet != OPPOSITE_FACET[2][pair % 3]     # the ZERO entries are never read
    held_pair, held_slot = holder // n_rt, holder % n_rt
    element, held_element = pair // 3, held_pair // 3
    # the same global DOF and the same patch vertex
    assert np.array_equal(dofs[held_slot, held_element][read], dofs[slot, element][read])
    assert np.array_equal(mesh.t[held_pair % 3, held_element][read],
                          mesh.t[pair % 3, element][read])
    # facet DOFs: the facet's first element; interior DOFs: themselves
    facet = mesh.t2f[np.maximum(local_facet, 0), element]
    on_facet = read & facet_slot
    assert np.array_equal(held_element[on_facet], mesh.f2t[0, facet[on_facet]])
    inside = ~facet_slot
    assert np.array_equal(holder[inside], (pair * n_rt + slot)[inside])


def test_tetrahedra_reproduce_an_affine_stress():
    """u = G x is the P1 solution (no load, t = S n): every patch's minimiser is psi_a S, so
    sigma* = S exactly (round-off: 1e-12 relative)."""
    lam, mu = CUBE_LAME
    stress = mu * (CUBE_STRAIN + CUBE_STRAIN.T) + lam * np.trace(CUBE_STRAIN) * np.eye(3)
    interior, fluxes, clamped, _, rho = cube_problem(
        3, 1, lambda x: 0.0 * x, lambda x: np.einsum("ij,j...->i...", stress, faces_normal(x)))
    np.testing.assert_allclose(interior.sigma_h[..., 0, 0], stress, atol=1e-12)
    assert np.abs(rho.nodal).max() < 1e-12   # u_h balances every patch
    rec = reconstruct(interior, fluxes, clamped)
    assert rec.imbalance < 1e-12
    assert np.abs(rec.values - stress[:, :, None, None]).max() < 1e-12 * np.abs(stress).max()


@pytest.mark.parametrize("order", [1, 2])
def test_tetrahedra_equilibrate_the_load_and_the_tractions(order):
    """div sigma* + f + rho = 0 in every element and sigma* n = t on the free faces, pointwise
    (f constant, t linear: both in the RT_k traces and divergences, so exactly, to round-off
    1e-10 of the data), evaluated by scikit-fem's own basis of the element."""
    force = np.array([1.0, -2.0, 0.5])

    def body_force(x):
        return force.reshape(3, *(1,) * (x.ndim - 1)) + 0.0 * x

    def traction(x):
        return np.array([x[1], 0.2 + 0.0 * x[0], x[0] - x[2]])

    interior, fluxes, clamped, facets, rho = cube_problem(2, order, body_force, traction)
    rec = reconstruct(interior, fluxes, clamped)
    assert rec.imbalance < 1e-10
    basis = interior.rt.basis()
    mesh = basis.mesh
    x = np.asarray(basis.global_coordinates())
    lam = np.asarray(mesh.mapping().invF(x))          # reference coordinates of the points
    bary = np.concatenate([1 - lam.sum(axis=0, keepdims=True), lam])  # (4, n_el, nq)
    load = np.einsum("vre,ven->ren", rho.nodal[mesh.t].transpose(0, 2, 1), bary)
    for r in range(3):
        div = np.asarray(basis.interpolate(rec.dofs[r]).div)
        residual = div + force[r] + load[r]
        assert np.abs(residual).max() < 1e-10 * (1 + np.abs(force).max())
    on_faces = FacetBasis(mesh, ElementTetRTk(order), facets=facets, intorder=4)
    y = np.asarray(on_faces.global_coordinates())
    for r in range(3):
        value = np.asarray(on_faces.interpolate(rec.dofs[r]))
        flux = np.einsum("ifp,ifp->fp", value, np.asarray(on_faces.normals))
        assert np.abs(flux - traction(y)[r]).max() < 1e-10


def planar_problem(k):
    """A smooth stress, load and traction on a locally refined `hertz` mesh, clamped along
    its bottom, rebalanced so that every patch off the clamp balances."""
    from estimators.guaranteed.equilibration import BoundaryData, boundary_balance, boundary_fluxes
    from estimators.guaranteed.patch_data import interior_data, rebalanced

    mesh = locally_refined_mesh()

    def sigma_h(rt):
        x = rt.global_coordinates()
        return np.array([[np.sin(x[0]) * x[1], x[0] ** 2], [x[0] ** 2, np.cos(x[1])]])

    interior = interior_data(mesh, sigma_h, lambda x: np.array([1.0 + x[1], -x[0]]), k,
                             2 * k + 2)
    bottom = mesh.p[1, mesh.facets].max(axis=0) <= mesh.p[1].min()
    boundary = mesh.boundary_facets()
    clamped = np.zeros(mesh.p.shape[1], dtype=bool)
    clamped[mesh.facets[:, boundary[bottom[boundary]]].ravel()] = True
    part = BoundaryData(boundary[~bottom[boundary]], lambda x: np.array([x[1], 0.3 + x[0]]))
    fluxes = boundary_fluxes(interior, [part])
    interior, _ = rebalanced(interior, interior.total
                             - boundary_balance(mesh.p.shape[1], fluxes), clamped)
    return interior, fluxes, clamped


@pytest.mark.parametrize("dim,k", [(2, 1), (2, 2), (2, 3), (3, 1), (3, 2)])
def test_condensing_the_element_interiors_keeps_the_stress(dim, k):
    """The patch systems with the element-interior unknowns eliminated first give the
    sigma* of the full systems (two solves of the same problem: round-off, 1e-9 of the
    largest DOF)."""
    if dim == 2:
        interior, fluxes, clamped = planar_problem(k)
    else:
        interior, fluxes, clamped, _, _ = cube_problem(
            2, k, lambda x: np.array([1.0, -2.0, 0.5]).reshape(3, *(1,) * (x.ndim - 1))
            + 0.0 * x, lambda x: np.array([x[1], 0.2 + 0.0 * x[0], x[0] - x[2]]))
    full = reconstruct(interior, fluxes, clamped, condense=False)
    condensed = reconstruct(interior, fluxes, clamped, condense=True)
    scale = np.abs(full.dofs).max()
    assert np.abs(condensed.dofs - full.dofs).max() < 1e-9 * scale

"""The symmetrising correction on tetrahedra (docs/theory.md, 14.5): the curls of the
potentials lie in RT_k row by row, keep the divergence and the prescribed tractions, and lower
the minimised objective."""

import numpy as np
import pytest
from skfem import Basis, ElementTetP2, FacetBasis, MeshTet

from conftest import CUBE_LAME, cube_problem
from estimators.guaranteed.equilibration import reconstruct
from estimators.guaranteed.raviart_thomas_tet import ElementTetRTk
from estimators.guaranteed.symmetrisation import WEIGHT
from estimators.guaranteed.symmetrisation_3d import (
    CurlEnergy,
    density,
    density_parts,
    node_blocks,
    symmetrised,
)

KORN = 1.0  # any weight: the properties below hold for every one


def body_force(x):
    return np.array([1.0, -2.0, 0.5]).reshape(3, *(1,) * (x.ndim - 1)) + 0.0 * x


def traction(x):
    return np.array([x[1], 0.2 + 0.0 * x[0], x[0] - x[2]])


def objective(rec, interior):
    """q(sigma* - sigma_h) of the module's minimisation, integrated."""
    Q = density(*CUBE_LAME, WEIGHT * KORN**2)
    diff = rec.values - interior.sigma_h
    return float((np.einsum("rcsd,rckp,sdkp->kp", Q, diff, diff) * rec.basis.dx).sum())


@pytest.mark.parametrize("order", [1, 2])
def test_the_correction_keeps_divergence_and_tractions_and_lowers_the_objective(order):
    interior, fluxes, clamped, facets, _ = cube_problem(2, order, body_force, traction)
    rec = reconstruct(interior, fluxes, clamped)
    sym = symmetrised(rec, interior, facets, CUBE_LAME, KORN)
    # the RT_k DOFs represent the corrected values (curl P2^3 lies in RT_k): round-off 1e-10
    scale = np.abs(sym.values).max()
    assert np.abs(interior.rt.values(sym.dofs) - sym.values).max() < 1e-10 * scale
    basis = interior.rt.basis()
    on_faces = FacetBasis(basis.mesh, ElementTetRTk(order), facets=facets, intorder=4)
    for r in range(3):   # div curl = 0; n . curl psi = 0 where psi = 0: round-off 1e-10
        div_before = np.asarray(basis.interpolate(rec.dofs[r]).div)
        div_after = np.asarray(basis.interpolate(sym.dofs[r]).div)
        assert np.abs(div_after - div_before).max() < 1e-10 * scale
        flux = [np.einsum("ifp,ifp->fp", np.asarray(on_faces.interpolate(dofs[r])),
                          np.asarray(on_faces.normals)) for dofs in (rec.dofs, sym.dofs)]
        assert np.abs(flux[1] - flux[0]).max() < 1e-10 * scale
    # CG from psi = 0 lowers the quadratic objective; measured 14.4 -> 4.76 (P1) and
    # 2.83 -> 1.70 (P2) on this mesh: at least 20 % asked
    assert objective(sym, interior) < 0.8 * objective(rec, interior)


def distorted_cube():
    mesh = MeshTet.init_tensor(*[np.linspace(0, 1, 3)] * 3)
    rng = np.random.default_rng(5)
    return MeshTet(mesh.p + 0.1 * rng.uniform(-1, 1, mesh.p.shape) * (mesh.p % 1 != 0),
                   mesh.t)


def element_matrices(energy, n_el):
    """The (n_el, 90, 90) matrices of ``energy``, one unit vector at a time."""
    columns = []
    for i in range(90):
        unit = np.zeros((n_el, 90))
        unit[:, i] = 1.0
        columns.append(energy.apply(unit.reshape(n_el, 9, 10)).reshape(n_el, 90))
    return np.stack(columns, axis=2)


def test_the_matrix_free_energy_is_q_of_the_curls():
    """x . A x against q(curl psi, curl psi) integrated by scikit-fem's P2 gradients on a
    rule of degree 4, curl written out component by component."""
    mesh, (lam, mu) = distorted_cube(), CUBE_LAME
    basis = Basis(mesh, ElementTetP2(), intorder=4)
    psi = np.random.default_rng(2).standard_normal((3, 3, basis.N))
    grad = np.array([[np.asarray(basis.interpolate(psi[r, b]).grad) for b in range(3)]
                     for r in range(3)])                                 # r b a k p
    curl = np.stack([grad[:, 2, 1] - grad[:, 1, 2], grad[:, 0, 2] - grad[:, 2, 0],
                     grad[:, 1, 0] - grad[:, 0, 1]], axis=1)              # r c k p
    Q = density(lam, mu, 0.7)
    expected = (np.einsum("rcsd,rckp,sdkp->kp", Q, curl, curl) * basis.dx).sum()
    energy = CurlEnergy.of(mesh, Q)
    local = psi[:, :, basis.element_dofs].reshape(9, 10, -1).transpose(2, 0, 1)
    found = (local * energy.apply(local)).sum()
    assert abs(found - expected) < 1e-11 * expected  # both exact for P1 curls: round-off


def test_the_node_blocks_are_the_diagonal_blocks_of_the_energy():
    mesh, (lam, mu) = distorted_cube(), CUBE_LAME
    dofs = Basis(mesh, ElementTetP2()).element_dofs                     # (10, n_el)
    energy = CurlEnergy.of(mesh, density(lam, mu, 0.7))
    matrices = element_matrices(energy, mesh.t.shape[1]).reshape(-1, 9, 10, 9, 10)
    n = int(dofs.max()) + 1
    expected = np.zeros((n, 9, 9))
    for j in range(10):
        np.add.at(expected, dofs[j], matrices[:, :, j, :, j])
    free = np.ones((9, n), dtype=bool)
    free[:, 0] = False                                                  # one node pinned
    inverse = node_blocks(energy, dofs, free, density_parts(lam, mu, 0.7))
    scale = np.abs(expected).max()
    assert np.abs(inverse[0]).max() == 0.0
    # the blocks against the energy's own products: round-off 1e-10
    assert np.abs(np.linalg.inv(inverse[1:]) - expected[1:]).max() < 1e-10 * scale

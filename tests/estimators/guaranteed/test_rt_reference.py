"""The patch problems' element integrals from reference-element data against scikit-fem's
quadrature of the same integrals on the physical elements (docs/theory.md, 13.2)."""

import numpy as np
import pytest
from skfem import Basis, ElementDG, ElementTriP1

from estimators.guaranteed import patches
from estimators.guaranteed.equilibrated import equilibrate
from estimators.guaranteed.patches import worker_count
from estimators.guaranteed.raviart_thomas import ElementTriRTk
from estimators.guaranteed.rt_reference import (
    ReferenceRT,
    element_matrices,
    patch_rhs,
    scalar_values,
)
from formulations import get_formulation, solve
from formulations.cells.p1_stiffness import barycentric_gradients
from formulations.elasticity import ELEMENTS
from scenes import get_scene


def values(basis) -> np.ndarray:
    return np.array([np.asarray(b[0]) for b in basis.basis])


@pytest.mark.parametrize("k", [1, 2, 3])
def test_reference_integrals_equal_physical_quadrature(k, skewed_mesh):
    mesh = skewed_mesh
    rt = Basis(mesh, ElementTriRTk(k), intorder=2 * k + 2)
    X, W = rt.quadrature
    dg = Basis(mesh, ElementDG(ELEMENTS[k]()), quadrature=rt.quadrature)
    hats = values(Basis(mesh, ElementTriP1(), quadrature=rt.quadrature))
    phi, q, dx = values(rt), values(dg), rt.dx
    div = np.array([b[0].div for b in rt.basis])
    sigma = np.random.default_rng(k).standard_normal((2, 2) + dx.shape)
    expected = {
        "mass": np.einsum("jiep,liep,ep->ejl", phi, phi, dx),
        "divergence": np.einsum("lep,jep,ep->elj", q, div, dx),
        "rhs": np.einsum("jkep,aep,rkep,ep->earj", phi, hats, sigma, dx),
        "data": np.einsum("rkep,ake,lep,ep->earl", sigma, barycentric_gradients(mesh)[0], q,
                          dx)}
    got = dict(zip(["mass", "divergence"],
                   element_matrices(mesh, k, X, W, scalar_values(ELEMENTS[k](), X)),
                   strict=True))
    got.update(zip(["rhs", "data"], patch_rhs(mesh, k, X, W, scalar_values(ELEMENTS[k](), X),
                                              sigma, barycentric_gradients(mesh)[0]),
                   strict=True))
    for name, value in expected.items():
        # the same sums in another order: round-off of the entries' size (seen ~5e-16)
        assert np.abs(got[name] - value).max() <= 1e-12 * np.abs(value).max(), name


def test_worker_count_honours_omp_num_threads(monkeypatch):
    monkeypatch.delenv("OMP_NUM_THREADS", raising=False)
    cores = worker_count()
    assert cores >= 1
    for setting, count in [("1", 1), ("x", cores), ("0", cores), (str(cores + 5), cores)]:
        monkeypatch.setenv("OMP_NUM_THREADS", setting)
        assert worker_count() == count, setting


def test_the_reconstruction_does_not_depend_on_the_thread_count(monkeypatch):
    """Each chunk of patches writes only its own unknowns: one thread and several give the
    same stress (bit for bit up to LAPACK's kernels, 1e-13 relative)."""
    scene = get_scene("paper")
    solution = solve(get_formulation("mixed")(scene, scene.mesh.refined(2)), "active-set")
    fields = []
    for setting in ("1", "4"):
        monkeypatch.setenv("OMP_NUM_THREADS", setting)
        monkeypatch.setattr(patches, "BATCH", 16)   # many chunks on a small mesh
        fields.append(equilibrate(scene, solution)[0].dofs)
    assert np.abs(fields[0] - fields[1]).max() <= 1e-13 * np.abs(fields[0]).max()


@pytest.mark.parametrize("k", [1, 2, 3])
def test_values_at_points_of_chosen_elements_are_scikit_fems(k, skewed_mesh):
    """``ReferenceRT.values_at`` at points inside some elements (in another order than the
    mesh's) against scikit-fem's interpolation there (round-off)."""
    rt = ReferenceRT.build(skewed_mesh, k, 2 * k + 2)
    dofs = np.random.default_rng(k).standard_normal((2, rt.N))
    cells = np.arange(skewed_mesh.t.shape[1])[::-3]
    X = np.array([[0.2, 0.6, 0.1], [0.3, 0.1, 0.7]])
    x = skewed_mesh.mapping().F(X, tind=cells)                            # (2, n, 3)
    basis = Basis(skewed_mesh, ElementTriRTk(k), quadrature=(X, np.ones(3)))
    expected = np.array([np.asarray(basis.interpolate(d))[:, cells] for d in dofs])
    got = rt.values_at(dofs, x, cells)
    assert np.abs(got - expected).max() <= 1e-12 * np.abs(expected).max()
    # the same points named by their reference coordinates: the basis evaluated once
    shared = rt.values_at(dofs, x, cells, reference=X)
    assert np.abs(shared - expected).max() <= 1e-12 * np.abs(expected).max()

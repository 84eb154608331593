"""The extensions d of the penetration on tetrahedra (docs/theory.md, 14.5)."""

import numpy as np
import pytest
from skfem.quadrature import get_quadrature
from skfem.refdom import RefTet

from estimators.guaranteed.contact_extension import discrete_gap
from estimators.guaranteed.contact_extension_3d import (
    EXTENSIONS_3D,
    SAMPLE_DIVISIONS,
    SurfaceExtension,
    fitted_extension,
    floor_extension,
    lattice,
)
from formulations import get_formulation, solve
from formulations.elasticity import stress_tensor_from_gradient
from scenes import get_scene


@pytest.fixture(scope="module")
def hertz():
    scene = get_scene("hertz-3d")
    mesh = scene.mesh.refined(1)
    sol = solve(get_formulation("vi")(scene, mesh, order=1), "active-set")
    clamped = np.zeros(mesh.p.shape[1], dtype=bool)
    clamped[mesh.facets[:, scene.dirichlet_facets(mesh)].ravel()] = True
    return scene, sol, clamped


@pytest.mark.parametrize("extend", EXTENSIONS_3D)
def test_d_n_stays_below_the_penetration_where_it_is_imposed(hertz, extend):
    scene, sol, clamped = hertz
    d = extend(scene, sol, clamped)
    t = lattice(SAMPLE_DIVISIONS)
    w = np.minimum(discrete_gap(scene, sol, t), 0.0)
    assert w.min() < 0   # u_h penetrates between its nodes: d has work to do
    # the defining inequality, to round-off of the vertex values (1e-12 of the penetration)
    assert (d.normal_part(sol.trace, t) - w).max() <= 1e-12 * abs(w.min())
    assert np.all(np.abs(d.nodal[:, clamped]) == 0.0)


def test_the_fit_costs_less_energy_than_the_floor(hertz):
    """Measured D: 0.168 (floor) and 0.123 (fit) on this level."""
    scene, sol, clamped = hertz
    lame, mesh = sol.elasticity.lame, sol.elasticity.mesh
    energies = [extend(scene, sol, clamped).energy(mesh, lame, sol.trace).sum()
                for extend in (floor_extension, fitted_extension)]
    assert np.sqrt(energies[1]) < 0.85 * np.sqrt(energies[0])


def test_the_bubbles_energy_against_differences_of_the_field(hertz):
    """a(d, d) of random face bubbles against central differences (step 1e-6) of d at the
    points of another rule (degree 6) in their tetrahedra: 1e-6 relative."""
    scene, sol, _ = hertz
    surface, mesh, lame = sol.trace, sol.elasticity.mesh, sol.elasticity.lame
    rng = np.random.default_rng(2)
    d = SurfaceExtension(np.zeros((3, mesh.p.shape[1])), rng.uniform(-1, 1, surface.size))
    energy = d.energy(mesh, lame, surface)
    X, W = get_quadrature(RefTet, 6)
    holders = np.unique(surface.element)
    mapping = mesh.mapping()
    x = np.asarray(mapping.F(X, tind=holders))                        # (3, m, nq)

    def field(points):
        out = np.zeros_like(points)
        for f in range(surface.size):
            k = np.searchsorted(holders, surface.element[f])
            corners = mesh.p[:, mesh.t[:, surface.element[f]]]
            lam = np.linalg.solve(np.vstack([corners, np.ones(4)]),
                                  np.vstack([points[:, k], np.ones(points.shape[2])]))
            face = [np.flatnonzero(mesh.t[:, surface.element[f]] == v)[0]
                    for v in surface.vertices[:, f]]
            out[:, k] += d.bubble[f] * 27 * lam[face].prod(axis=0) * surface.normal[:, f, None]
        return out

    step = 1e-6
    grad = np.zeros((3, 3) + x.shape[1:])
    for k in range(3):
        shift = np.zeros((3, 1, 1))
        shift[k] = step
        grad[:, k] = (field(x + shift) - field(x - shift)) / (2 * step)
    density = np.einsum("ijmq,ijmq->mq", stress_tensor_from_gradient(grad, *lame), grad)
    expected = (density @ W) * np.abs(mapping.detA[holders])
    np.testing.assert_allclose(energy[holders], expected, rtol=1e-6)

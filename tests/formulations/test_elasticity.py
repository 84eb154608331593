"""Patch tests of the P1 elasticity assembly against hand-computed plane-stress values."""

import numpy as np
import pytest

from formulations.cells import family_of
from formulations.elasticity import (
    assemble_elasticity,
    count_free_dofs,
    predict_refined_free_dofs,
    stress_from_gradient,
    von_mises,
)
from scenes import get_scene


@pytest.fixture(scope="module")
def elasticity():
    scene = get_scene("paper")
    mesh = scene.mesh.refined(2)
    # perturb interior vertices so that the mesh is not symmetric (a stronger patch test)
    rng = np.random.default_rng(0)
    interior = mesh.interior_nodes()
    p = mesh.p.copy()
    p[:, interior] += 0.02 * rng.uniform(-1, 1, (2, interior.size))
    return assemble_elasticity(scene, type(mesh)(p, mesh.t))


def field(elasticity, A, b):
    """DOF vector of the linear field u(x) = A x + b."""
    u = np.zeros(elasticity.basis.N)
    p = elasticity.mesh.p
    for c in range(2):
        u[elasticity.basis.nodal_dofs[c]] = A[c, 0] * p[0] + A[c, 1] * p[1] + b[c]
    return u


def test_linear_field_has_zero_interior_residual_and_exact_energy(elasticity):
    A, b = np.array([[0.3, -0.2], [0.5, 0.1]]), np.array([0.01, -0.02])
    u = field(elasticity, A, b)
    r = elasticity.K @ u
    interior_dofs = elasticity.basis.nodal_dofs[:, elasticity.mesh.interior_nodes()].ravel()
    assert np.abs(r[interior_dofs]).max() < 1e-9 * np.abs(r).max()
    # plane stress by hand: sigma = E/(1-nu^2) [[1, nu, 0], [nu, 1, 0], [0, 0, (1-nu)/2]] eps
    E, nu = 70000.0, 0.33
    eps = np.array([A[0, 0], A[1, 1], A[0, 1] + A[1, 0]])  # engineering shear strain
    D = E / (1 - nu**2) * np.array([[1, nu, 0], [nu, 1, 0], [0, 0, (1 - nu) / 2]])
    exact = 0.5 * 4.0 * eps @ D @ eps  # |Omega| = 4
    assert 0.5 * u @ r == pytest.approx(exact, rel=1e-12)
    # the element stresses are the same hand-computed constant everywhere
    s = elasticity.element_stress(u)
    assert np.allclose(s, (D @ eps)[:, None], rtol=1e-12, atol=1e-9)


@pytest.mark.parametrize("rotation", [0.0, 0.7])
def test_rigid_body_motions_have_zero_strain_energy(elasticity, rotation):
    A = np.array([[0.0, -rotation], [rotation, 0.0]])
    u = field(elasticity, A, np.array([0.3, -0.4]))
    scale = np.abs(elasticity.K).max() * (u @ u)
    assert abs(u @ (elasticity.K @ u)) < 1e-13 * scale


def test_clamped_dofs_are_the_top_edge(elasticity):
    mesh = elasticity.mesh
    clamped = np.setdiff1d(np.arange(elasticity.basis.N), elasticity.free)
    top = np.flatnonzero(np.isclose(mesh.p[1], 1.0))
    assert set(clamped) == set(elasticity.basis.nodal_dofs[:, top].ravel())


def test_von_mises_of_uniaxial_and_pure_shear():
    assert von_mises(np.array([[2.0], [0.0], [0.0]])) == pytest.approx([2.0])
    assert von_mises(np.array([[0.0], [0.0], [1.0]])) == pytest.approx([np.sqrt(3.0)])
    grad = np.zeros((2, 2, 1))
    grad[0, 1, 0] = 1.0
    assert stress_from_gradient(grad, 2.0, 3.0)[:, 0] == pytest.approx([0.0, 0.0, 3.0])


@pytest.mark.parametrize("name", ["paper", "hertz", "free-boundary", "thin", "corner"])
@pytest.mark.parametrize("order", [1, 2, 3])
def test_the_next_levels_size_is_known_before_refining(name, order):
    # the refinement loop stops on this prediction: it must be the count of the mesh that
    # refining gives, exactly (an integer), for adaptive and uniform refinement
    scene = get_scene(name)
    rng = np.random.default_rng(11)
    mesh = scene.mesh
    for fraction in (0.05, 0.3, 1.0, None):
        marked = (None if fraction is None else
                  np.flatnonzero(rng.random(mesh.t.shape[1]) < fraction))
        plan = family_of(mesh).refinement(mesh, marked)
        assert predict_refined_free_dofs(scene, plan, order) == count_free_dofs(
            scene, plan.refined, order)
        mesh = plan.refined

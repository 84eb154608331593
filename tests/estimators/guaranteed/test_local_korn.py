"""Korn constants from the geometry (estimators.guaranteed.local_korn): upper bounds, checked
against discrete Korn constants, which approach the true ones from below."""

import numpy as np
import pytest
from scipy.linalg import eigh
from skfem import Basis, BilinearForm, ElementTriP2, ElementVector, LinearForm, MeshTri, asm
from skfem.helpers import ddot, grad, sym_grad

from estimators.guaranteed.local_korn import element_korn, korn_from_angle, vertex_korn


@BilinearForm
def _gradients(u, v, w):
    return ddot(grad(u), grad(v))


@BilinearForm
def _strains(u, v, w):
    return ddot(sym_grad(u), sym_grad(v))


@LinearForm
def _rotation(v, w):
    return v.grad[1, 0] - v.grad[0, 1]


def discrete_korn(mesh) -> float:
    """max ||grad v||^2 / ||eps(v)||^2 over P2 fields v with int rot v = 0 and zero mean:
    a lower bound of the domain's Korn constant (a Rayleigh quotient over a subspace)."""
    basis = Basis(mesh, ElementVector(ElementTriP2()))
    G, E = asm(_gradients, basis).toarray(), asm(_strains, basis).toarray()
    translations = np.zeros((basis.N, 2))
    translations[0::2, 0] = translations[1::2, 1] = 1.0  # interleaved components
    constraints = np.column_stack([asm(_rotation, basis), translations])
    q, _ = np.linalg.qr(constraints, mode="complete")
    Z = q[:, constraints.shape[1]:]
    return float(eigh(Z.T @ G @ Z, Z.T @ E @ Z, eigvals_only=True).max())


def triangle(points) -> MeshTri:
    return MeshTri(np.array(points, dtype=float).T, np.array([[0], [1], [2]]))


def test_the_disc_is_the_sharp_case():
    """On a disc (theta = pi / 2 from its centre) K = 4, the disc's Korn constant (Horgan and
    Payne); discrete P2 fields on an inscribed 256-gon reach it from below to 1e-4."""
    assert korn_from_angle(np.pi / 2) == pytest.approx(4.0, rel=1e-14)
    assert discrete_korn(MeshTri.init_circle(3)) == pytest.approx(4.0, rel=1e-4)


@pytest.mark.parametrize("points", [[(0, 0), (1, 0), (0, 1)],
                                    [(0, 0), (1, 0), (0.5, np.sqrt(3) / 2)],
                                    [(0, 0), (2, 0), (0.3, 0.4)]])
def test_a_triangles_bound_lies_above_its_discrete_korn_constant(points):
    """K_T from the incentre against P2 on the triangle refined three times (measured: 52.5
    against 26.1 for the right isosceles triangle, 29.9 against 15.3 equilateral)."""
    mesh = triangle(points)
    bound = element_korn(mesh)[0]
    assert bound == pytest.approx(korn_from_angle(np.min(angles(points)) / 2), rel=1e-12)
    assert discrete_korn(mesh.refined(3)) <= bound


def angles(points) -> np.ndarray:
    p = np.array(points, dtype=float)
    out = []
    for i in range(3):
        u, w = p[(i + 1) % 3] - p[i], p[(i + 2) % 3] - p[i]
        out.append(np.arccos(u @ w / np.linalg.norm(u) / np.linalg.norm(w)))
    return np.array(out)


def test_vertex_patches_of_a_structured_mesh():
    """An interior vertex of the diagonal grid sees its hexagon's edges at 45 degrees at
    least (hand count: the six triangles' outer angles are 45 and 90 degrees), so K_z =
    2 / sin^2(pi / 8); every patch's bound lies above its discrete Korn constant."""
    mesh = MeshTri.init_tensor(np.linspace(0, 1, 5), np.linspace(0, 1, 5))
    korn = vertex_korn(mesh)
    inner = np.setdiff1d(np.arange(mesh.p.shape[1]), mesh.boundary_nodes())
    assert korn[inner] == pytest.approx(2 / np.sin(np.pi / 8) ** 2, rel=1e-12)
    for vertex in (6, 1, 0, 4):  # interior, edge, and both kinds of corner
        patch = np.flatnonzero((mesh.t == vertex).any(axis=0))
        local = MeshTri(mesh.p, mesh.t[:, patch]).remove_unused_nodes()
        assert np.isfinite(korn[vertex])
        assert discrete_korn(local.refined(2)) <= korn[vertex]

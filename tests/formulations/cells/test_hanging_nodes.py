"""Hanging-node constraints of Q1 and Q2: the patch test (a displacement of the element's
space is reproduced to round-off on a mesh with hanging nodes) and continuity across every
edge with a hanging node."""

import numpy as np
import pytest
from scipy.sparse.linalg import spsolve
from skfem import Basis, LinearForm, asm
from skfem.helpers import dot

from conftest import square_scene
from formulations.cells.hanging_nodes import prolongation
from formulations.elasticity import assemble_elasticity
from scenes.quad_hierarchy import QuadHierarchy


def graded_hierarchy() -> QuadHierarchy:
    hierarchy = QuadHierarchy.from_tensor(np.linspace(-1, 1, 3), np.linspace(-1, 1, 3))
    for _ in range(4):
        centres = hierarchy.p[:, hierarchy.cells[:, hierarchy.leaves]].mean(axis=1)
        hierarchy = hierarchy.refined(
            [np.argmin(np.linalg.norm(centres - np.array([[0.3], [-0.2]]), axis=0))])
    return hierarchy


def fields(order: int, lam: float, mu: float):
    """A displacement of Q_order (bilinear, biquadratic) and the body force f = -div sigma
    that it balances, derived by hand from sigma = lam tr(eps) I + 2 mu eps."""
    if order == 1:  # u = (xy + x/10, 3y/10 - x/5 + xy/20)
        return (lambda x: np.array([x[0] * x[1] + 0.1 * x[0],
                                    0.3 * x[1] - 0.2 * x[0] + 0.05 * x[0] * x[1]]),
                np.array([-0.05 * (lam + mu), -(lam + mu)]))
    return (lambda x: np.array([x[0] ** 2 + 0.5 * x[0] * x[1], x[1] ** 2 - x[0] * x[1]]),
            np.array([-(3 * mu + lam), -(4.5 * mu + 2.5 * lam)]))


@pytest.fixture
def scene():
    return square_scene(lambda x: np.full(x.shape[1:], 1.0), young_modulus=1000.0,
                        poisson_ratio=0.3)


@pytest.mark.parametrize("order", [1, 2])
def test_a_displacement_of_the_element_space_is_reproduced(scene, order):
    hierarchy = graded_hierarchy()
    assert hierarchy.hanging()[0].size == 22
    elasticity = assemble_elasticity(scene, hierarchy.mesh(), order)
    basis, P = elasticity.basis, elasticity.constraint
    exact, force = fields(order, *elasticity.lame)

    @LinearForm
    def body(v, w):
        return dot(force[:, None, None] + 0.0 * w.x, v)

    F = P.T @ asm(body, Basis(basis.mesh, basis.elem, intorder=2 * order + 1))
    component = np.zeros(basis.N, dtype=int)
    for dofs in (basis.nodal_dofs, basis.facet_dofs, basis.interior_dofs):
        if dofs.size:
            component[dofs[1]] = 1
    values = exact(basis.doflocs)[component, np.arange(basis.N)]
    _, kept = prolongation(hierarchy, basis)  # the cell DOFs that are conforming DOFs
    conforming = values[kept]
    on_boundary = np.zeros(basis.N, dtype=bool)
    on_boundary[basis.get_dofs(elasticity.mesh.boundary_facets()).all()] = True
    fixed = np.asarray(P.T @ on_boundary.astype(float)).ravel() > 0
    K, u = (P.T @ elasticity.K @ P).tocsr(), conforming.copy()
    u[~fixed] = spsolve(K[~fixed][:, ~fixed].tocsc(), F[~fixed] - K[~fixed][:, fixed] @ u[fixed])
    # round-off of a sparse solve with condition ~1e3: 1e-12 of the field's size
    assert np.abs(P @ u - values).max() <= 1e-12 * np.abs(values).max()


@pytest.mark.parametrize("order", [1, 2])
def test_p_u_is_continuous_across_every_edge_with_a_hanging_node(scene, order):
    hierarchy = graded_hierarchy()
    elasticity = assemble_elasticity(scene, hierarchy.mesh(), order)
    P = elasticity.constraint
    u = P @ np.random.default_rng(1).standard_normal(P.shape[1])
    _, a, b = hierarchy.hanging()
    pa, pb = hierarchy.p[:, a], hierarchy.p[:, b]
    points = pa[:, :, None] + (pb - pa)[:, :, None] * np.array([0.1, 0.3, 0.45, 0.55, 0.8])
    normal = np.array([-(pb - pa)[1], (pb - pa)[0]]) / np.linalg.norm(pb - pa, axis=0)
    delta = 1e-9  # just inside either side: the difference is delta x the gradient, O(1e-8)
    left = (points + delta * normal[:, :, None]).reshape(2, -1)
    right = (points - delta * normal[:, :, None]).reshape(2, -1)
    jump = elasticity.basis.probes(left) @ u - elasticity.basis.probes(right) @ u
    assert np.abs(jump).max() <= 1e-6 * np.abs(u).max()
    # without the constraints the two sides differ at O(1)
    free = np.random.default_rng(1).standard_normal(elasticity.basis.N)
    assert np.abs(elasticity.basis.probes(left) @ free
                  - elasticity.basis.probes(right) @ free).max() > 0.1

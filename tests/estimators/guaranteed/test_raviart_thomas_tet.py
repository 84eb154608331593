"""RT_k on tetrahedra (``estimators.guaranteed.raviart_thomas_tet``): dimension, divergence, normal
continuity across faces on a distorted mesh, and a mixed Poisson problem that converges at the
element's order."""

import numpy as np
import pytest
import scipy.sparse as sp
from scipy.sparse.linalg import spsolve
from skfem import (
    Basis,
    BilinearForm,
    ElementDG,
    ElementTetP1,
    ElementTetP2,
    LinearForm,
    MeshTet,
    asm,
)
from skfem.helpers import dot

from bench.measure.slope import fit_slope
from estimators.guaranteed.raviart_thomas_tet import ElementTetRTk, monomials, sorted_tetrahedra


def _distorted_mesh(n: int, ordered: bool = True) -> MeshTet:
    """The unit cube in 6 n^3 tetrahedra, inner vertices moved by up to 0.15 h and the
    vertices renumbered at random (seeded), so that two tetrahedra see a shared face as
    different local faces once their vertices are sorted (``ordered``)."""
    grid = np.linspace(0.0, 1.0, n + 1)
    mesh = MeshTet.init_tensor(grid, grid, grid)
    rng = np.random.default_rng(1)
    inner = ~np.isin(np.arange(mesh.p.shape[1]), mesh.boundary_nodes())
    p = mesh.p.copy()
    p[:, inner] += rng.uniform(-0.15, 0.15, (3, inner.sum())) / n
    order = rng.permutation(p.shape[1])                # new number of each old vertex
    new_p = np.empty_like(p)
    new_p[:, order] = p
    mesh = MeshTet(new_p, rng.permuted(order[mesh.t], axis=0))  # each one's vertices shuffled
    return sorted_tetrahedra(mesh) if ordered else mesh


@pytest.mark.parametrize("k", [1, 2, 3])
def test_dimension_and_divergence(k):
    """(k + 1)(k + 2)(k + 4) / 2 functions, 4 faces of (k + 1)(k + 2) / 2 DOFs; the divergence
    lbasis returns is that of its values, by central differences (step 1e-5: error ~1e-9)."""
    element = ElementTetRTk(k)
    assert element._coefficients.shape[0] == (k + 1) * (k + 2) * (k + 4) // 2
    assert 4 * element.facet_dofs + element.interior_dofs == element._coefficients.shape[0]
    X = np.random.default_rng(k).uniform(0.05, 0.3, (3, 7))
    h = 1e-5
    for i in range(element._coefficients.shape[0]):
        _, div = element.lbasis(X, i)
        numeric = sum((element.lbasis(X + h * np.eye(3)[:, [d]], i)[0][d]
                       - element.lbasis(X - h * np.eye(3)[:, [d]], i)[0][d]) / (2 * h)
                      for d in range(3))
        assert np.allclose(div, numeric, rtol=0, atol=1e-6 * max(1.0, np.abs(div).max()))


def test_monomials_are_rt_k():
    """P_k^3 + x P~_k: 3 dim P_k + dim P~_k functions, divergence P_k (k = 2)."""
    values, divs = monomials(2, np.random.default_rng(0).uniform(size=(3, 4)))
    assert values.shape == (3 * 10 + 6, 3, 4) and divs.shape == (36, 4)


@pytest.mark.parametrize("k", [1, 2, 3])
def test_normal_components_agree_across_every_inner_face(k):
    """A random global RT_k field: at 4 points of every inner face, phi . n from the two
    tetrahedra that share it agree (relative 1e-10), on a distorted mesh, where a face's points
    or normal sign taken in another order by the two sides would differ by O(1)."""
    mesh = _distorted_mesh(2)
    local = [(mesh.t2f[:, mesh.f2t[side]] == np.arange(mesh.facets.shape[1])).argmax(axis=0)
             for side in (0, 1)]
    assert np.any((local[0] != local[1]) & (mesh.f2t[1] >= 0))  # the case worth testing
    basis = Basis(mesh, ElementTetRTk(k), intorder=2)
    field = np.random.default_rng(k).standard_normal(basis.N)
    faces = np.flatnonzero(mesh.f2t[1] >= 0)
    bary = np.array([[0.6, 0.2, 0.2], [0.2, 0.6, 0.2], [0.2, 0.2, 0.6], [1 / 3, 1 / 3, 1 / 3]])
    corners = mesh.p[:, mesh.facets[:, faces]]                           # (3, 3, n_f)
    points = np.einsum("qv,dvf->dfq", bary, corners)                     # (3, n_f, 4)
    normal = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0], axis=0)
    sides = [_values_in(basis, field, points, mesh.f2t[side, faces]) for side in (0, 1)]
    flux = [np.einsum("dfq,df->fq", values, normal) for values in sides]
    assert np.abs(flux[0] - flux[1]).max() <= 1e-10 * np.abs(flux[0]).max()


def _values_in(basis, field, points, cells):
    """The field's values (3, n_f, nq) at points (3, n_f, nq), row f's in element cells[f]:
    the contravariant Piola map of the reference functions, with scikit-fem's orientation."""
    mesh, element = basis.mesh, basis.elem
    origin = mesh.p[:, mesh.t[0, cells]]                                   # (3, n_f)
    J = (mesh.p[:, mesh.t[1:, cells]] - origin[:, None]).transpose(2, 0, 1)  # (n_f, 3, 3)
    local = np.linalg.solve(J, (points - origin[:, :, None]).transpose(1, 0, 2))
    X = local.transpose(1, 0, 2).reshape(3, -1)                            # (3, n_f nq)
    mapping = mesh.mapping()
    out = np.zeros((points.shape[1], 3, points.shape[2]))
    for i in range(basis.element_dofs.shape[0]):
        reference = element.lbasis(X, i)[0].reshape(3, *points.shape[1:])  # (3, n_f, nq)
        weight = (field[basis.element_dofs[i, cells]] * element.orient(mapping, i)[cells]
                  / np.abs(np.linalg.det(J)))
        out += weight[:, None, None] * np.einsum("fij,jfq->fiq", J, reference)
    return out.transpose(1, 0, 2)


@pytest.mark.slow  # mixed Poisson on 6 n^3 tetrahedra, n = 3 and 6: ~30 s
@pytest.mark.parametrize("k", [1, 2])
def test_mixed_poisson_converges_at_order_k_plus_one(k):
    """-div grad u = f on the unit cube, u = 0 on its boundary (natural in the mixed form),
    u = sin(pi x) sin(pi y) sin(pi z): (sigma, tau) + (u, div tau) = 0, (div sigma, v) =
    -(f, v), sigma in RT_k, u in P_k DG. ||u - u_h|| falls like h^(k+1) (fitted slope within
    0.3 of it over h = 1/3, 1/6); a space whose normals did not match across faces would not
    converge."""
    errors, sizes = [], []
    for n in (3, 6):
        grid = np.linspace(0.0, 1.0, n + 1)
        mesh = sorted_tetrahedra(MeshTet.init_tensor(grid, grid, grid))
        rt = Basis(mesh, ElementTetRTk(k), intorder=2 * k + 2)
        dg = rt.with_element(ElementDG(ElementTetP1() if k == 1 else ElementTetP2()))
        mass = asm(BilinearForm(lambda s, t, w: dot(s, t)), rt)
        div = asm(BilinearForm(lambda s, v, w: s.div * v), rt, dg)
        exact = np.sin(np.pi * np.asarray(rt.global_coordinates())).prod(axis=0)
        load = asm(LinearForm(lambda v, w: 3 * np.pi**2 * w.exact * v), dg, exact=exact)
        system = sp.bmat([[mass, div.T], [div, None]]).tocsc()
        x = spsolve(system, np.concatenate([np.zeros(rt.N), -load]))
        u_h = np.asarray(dg.interpolate(x[rt.N:]))
        errors.append(np.sqrt(((u_h - exact) ** 2 * dg.dx).sum()))
        sizes.append(1.0 / n)
    slope = fit_slope(sizes, errors).slope
    assert abs(slope - (k + 1)) < 0.3, (slope, errors)


def test_unsorted_tetrahedra_break_the_normal_continuity():
    """Why ``sorted_tetrahedra``: on the same mesh with each tetrahedron's vertices in the
    renumbering's order, a shared face's points differ between its two sides (k = 2)."""
    mesh = _distorted_mesh(2, ordered=False)
    basis = Basis(mesh, ElementTetRTk(2), intorder=2)
    field = np.random.default_rng(2).standard_normal(basis.N)
    faces = np.flatnonzero(mesh.f2t[1] >= 0)
    corners = mesh.p[:, mesh.facets[:, faces]]
    points = np.einsum("qv,dvf->dfq", np.array([[0.6, 0.2, 0.2]]), corners)
    normal = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0], axis=0)
    flux = [np.einsum("dfq,df->fq", _values_in(basis, field, points, mesh.f2t[side, faces]),
                      normal) for side in (0, 1)]
    assert np.abs(flux[0] - flux[1]).max() > 1e-3 * np.abs(flux[0]).max()

"""The oscillation of a jumping body force bounded element by element with an RT_0 flux on
sub-simplices (estimators.guaranteed.jump_flux)."""

import numpy as np
import pytest
import scipy.sparse.linalg as spla
from skfem import (
    Basis,
    BilinearForm,
    ElementTetP0,
    ElementTetP2,
    LinearForm,
    MeshTet,
    asm,
)
from skfem.helpers import dot
from skfem.quadrature import get_quadrature
from skfem.refdom import RefTet

from estimators.guaranteed import jump_flux
from estimators.guaranteed.jump_flux import (
    FluxOscillation,
    _least_flux,
    _sub_moments,
    flux_oscillation,
)
from estimators.guaranteed.oscillation import oscillation
from estimators.guaranteed.raviart_thomas_tet import sorted_tetrahedra
from estimators.guaranteed.rt_reference import ReferenceRT
from estimators.guaranteed.sub_simplices import sub_simplices
from formulations.cells.load import mapped_rule
from formulations.elasticity import element_diameters
from scenes import get_scene

CORNERS = np.array([[0.1, 0.0, 0.0], [1.2, 0.1, 0.0], [0.2, 0.9, 0.1], [0.0, 0.3, 1.1]]).T
JUMP = 3 / 8  # in the element's reference coordinates: a plane of the 8^3-fold refinement


def _element():
    return MeshTet(CORNERS, np.array([[0], [1], [2], [3]]))


def _jumping(x):
    """A body force that jumps across the plane x^_0 = JUMP of the one tetrahedron."""
    A = CORNERS[:, 1:] - CORNERS[:, :1]
    reference = np.einsum("ij,j...->i...", np.linalg.inv(A), x - CORNERS[:, :1].reshape(
        (3,) + (1,) * (x.ndim - 1)))
    side = reference[0] > JUMP
    return np.array([np.where(side, 1.0 + x[1], -x[0]), np.where(side, x[2], 2.0),
                     np.where(side, 0.5, x[0] * x[1])])


def test_a_polynomial_load_leaves_no_rough_element():
    assert flux_oscillation(_element().refined(1), lambda x: np.array([1 + x[0], x[1] * 2,
                                                                        3 + x[2]]), 1) is None


def test_the_flux_balances_the_piecewise_constant_part():
    """(r_0, v)_T = -(tau, grad v)_T for a quadratic v: tau . n = 0 on the boundary of T and
    div tau = r_0 on every sub-tetrahedron."""
    mesh, sub = _element(), sub_simplices(RefTet, 2)
    moments, *_ = _sub_moments(mesh, np.array([0]), _jumping, 1, sub)
    A = mesh.mapping().A[:, :, 0]
    _, coefficients = _least_flux(A[None], moments, sub)
    X, W = mapped_rule(sub.corners, get_quadrature(RefTet, 2))
    det = abs(np.linalg.det(A))
    x = np.einsum("ij,jsq->isq", A, X) + CORNERS[:, :1, None]
    tau = np.einsum("ac,rcsq->rasq", A, sub.values(coefficients, X)[0]) / det

    def v(x):
        return 1 + x[0] ** 2 - x[1] * x[2] + 0.5 * x[2]

    grad_v = np.array([2 * x[0], -x[2], -x[1] + 0.5])
    left = np.einsum("sr,s->r", moments[0] / (det * sub.volume),
                     (v(x) * W * det).sum(axis=1))
    right = -np.einsum("rasq,asq,sq->r", tau, grad_v, W * det)
    # both exact (degree 2): round-off
    assert np.allclose(left, right, rtol=1e-10, atol=1e-14)


def _residual(f):
    """r = f - Pi_1 f on T, Pi_1 f from exact integrals on the element refined three times
    (the jump lies on its faces), and ||r||_T."""
    fine = Basis(_element().refined(3), ElementTetP0(), intorder=5)
    x, dx = np.asarray(fine.global_coordinates()), fine.dx
    affine = np.array([np.ones_like(x[0]), *x])                          # (4, n, nq)
    gram = np.einsum("anq,bnq,nq->ab", affine, affine, dx)
    coefficients = np.linalg.solve(gram, np.einsum("rnq,anq,nq->ar", f(x), affine, dx))

    def r(x):
        return f(x) - np.einsum("ar,a...->r...", coefficients,
                                np.array([np.ones_like(x[0]), *x]))

    return r, np.sqrt((r(x) ** 2 * dx).sum())


def _dual_norm(r):
    """sup over P2 on the element refined three times of (r, v) / ||grad v||, rows
    together: a lower bound of the true dual norm."""
    basis = Basis(_element().refined(3), ElementTetP2(), intorder=5)
    K = asm(BilinearForm(lambda u, v, w: dot(u.grad, v.grad)), basis)
    keep = np.arange(1, basis.N)  # v = 0 at one node: r is orthogonal to the constants
    total = 0.0
    for row in range(3):
        b = asm(LinearForm(lambda v, w, row=row: r(w.x)[row] * v), basis)
        total += b[keep] @ spla.spsolve(K[keep][:, keep].tocsc(), b[keep])
    return np.sqrt(total)


def _quadratic(x):
    return np.array([1.0 + x[1] * x[0], x[2] ** 2 - x[0], 0.5 + x[0] * x[1] - x[2]])


# measured osc / poincare: 0.32 (a jump, 64 sub-tetrahedra), 0.58 (smooth, 8)
@pytest.mark.parametrize("f, levels, ratio", [(_jumping, 2, 0.5), (_quadratic, 1, 0.7)])
def test_the_bound_lies_above_the_dual_norm_and_well_below_poincare(f, levels, ratio):
    mesh = _element()
    jump = flux_oscillation(mesh, f, 1, levels, elements=np.array([0]))
    r, norm = _residual(f)
    dual, osc = _dual_norm(r), np.sqrt(jump.osc_squares[0])
    poincare = element_diameters(mesh)[0] / np.pi * norm
    # the bound must hold (the P2 dual norm is below the true one)
    assert dual <= osc
    # and be worth its cost
    assert osc <= ratio * poincare


def test_a_body_force_in_p1_leaves_no_defect():
    """Moments of round-off size everywhere: the defect is measured against f, not them."""
    mesh = _element().refined(1)
    flux = flux_oscillation(mesh, lambda x: np.array([1 + x[0], 2 * x[1], -x[2]]), 1, 1,
                            elements=np.arange(mesh.t.shape[1]))
    assert flux.divergence_defect < 1e-12   # round-off
    assert np.sqrt(flux.osc_squares).max() < 1e-12


def test_oscillation_takes_each_part_on_its_own_elements():
    scene = get_scene("free-boundary-3d")
    rt = ReferenceRT.build(sorted_tetrahedra(scene.mesh), 1, 5)
    plain = oscillation(scene, rt, [])
    parts = [FluxOscillation(np.array([0, 1]), np.zeros(2), np.array([4.0, 9.0]), 0.0),
             FluxOscillation(np.array([2]), np.zeros(1), np.array([16.0]), 0.0)]
    out = oscillation(scene, rt, [], parts[0], None, parts[1])
    assert np.array_equal(out[:3], [2.0, 3.0, 4.0])
    assert np.array_equal(out[3:], plain[3:])


def test_inside_sigma_star_a_zero_gap_leaves_the_flux_itself():
    """With g = 0, lambda = 0 and 2 mu = 1, ||C^-1/2 sym tau||^2 + ||skw tau||^2 = ||tau||^2:
    the values of tau at the sub-simplices' points against its mass-matrix norm."""
    mesh = _element().refined(1)
    jump = flux_oscillation(mesh, _jumping, 1, lame=(0.0, 0.5),
                            gap=lambda x, cells, X: np.zeros((3, 3, *x.shape[1:])))
    assert jump.combined and jump.elements.size > 0
    # the same integral of a degree-2 polynomial two ways: round-off
    assert np.allclose(jump.symmetric + jump.skew, jump.flux, rtol=1e-10)
    assert np.array_equal(jump.osc_squares, jump.remainder)   # tau is inside sigma*


def test_a_gap_without_lame_parameters_is_refused():
    with pytest.raises(ValueError, match="gap and lame"):
        flux_oscillation(_element(), _jumping, 1, gap=lambda x, cells, X: 0 * x)


def test_batches_and_shapes_do_not_change_the_terms(monkeypatch):
    mesh = _element().refined(1)
    whole = flux_oscillation(mesh, _jumping, 1)
    monkeypatch.setattr(jump_flux, "CHUNK", 3)
    batched = flux_oscillation(mesh, _jumping, 1)
    assert np.allclose(batched.flux, whole.flux, rtol=1e-12)
    assert np.allclose(batched.remainder, whole.remainder, rtol=1e-12)
    # every moment sums to zero on its element: round-off
    assert whole.divergence_defect < 1e-12


def test_the_remainder_is_poincare_on_every_sub_simplex():
    """sum_S (h_S / pi)^2 ||r - mean_S r||_S^2 for a quadratic f (no jump: exact rules),
    recomputed on scikit-fem's mesh of the 64 mapped sub-tetrahedra, h_S its diameters."""
    mesh, sub = _element(), sub_simplices(RefTet, 2)
    A = mesh.mapping().A[:, :, 0]
    points = np.einsum("ij,skj->isk", A, sub.corners) + CORNERS[:, :1, None]  # (3, 64, 4)
    nodes, index = np.unique(np.round(points.reshape(3, -1), 12), axis=1, return_inverse=True)
    pieces = MeshTet(nodes, index.reshape(-1, 4).T)
    basis = Basis(pieces, ElementTetP0(), intorder=6)
    x, dx = np.asarray(basis.global_coordinates()), basis.dx
    affine = np.array([np.ones_like(x[0]), *x])
    gram = np.einsum("anq,bnq,nq->ab", affine, affine, dx)
    f = _quadratic(x)
    r = f - np.einsum("ar,anq->rnq", np.linalg.solve(gram, np.einsum("rnq,anq,nq->ar", f,
                                                                       affine, dx)), affine)
    mean = (r * dx).sum(axis=2, keepdims=True) / dx.sum(axis=1)[None, :, None]
    expected = ((element_diameters(pieces) / np.pi) ** 2
                * (((r - mean) ** 2).sum(axis=0) * dx).sum(axis=1)).sum()
    _, remainder, *_ = jump_flux._chunk_terms(mesh, np.array([0]), _quadratic, 1, 2, None,
                                              None)
    # both integrate piecewise quartics exactly: round-off
    assert remainder[0] == pytest.approx(expected, rel=1e-9)

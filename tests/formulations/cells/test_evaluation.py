"""Point evaluation of finite element fields."""

import numpy as np
import pytest
from skfem import Basis, MeshTri

from formulations.cells.evaluation import evaluate_at
from formulations.elasticity import vector_element


@pytest.mark.parametrize("order", [1, 2, 3])
def test_the_vector_lagrange_shortcut_is_scikit_fems_gbasis(order):
    """``evaluate_at`` maps the reference gradients with one inverse Jacobian for all basis
    functions; scikit-fem's ``gbasis`` (one per function) must give the same numbers."""
    rng = np.random.default_rng(1)
    square = MeshTri.init_sqsymmetric().refined(3)
    inner = (square.p > 0) & (square.p < 1)
    mesh = MeshTri(square.p + 0.01 * rng.standard_normal(square.p.shape) * inner, square.t)
    basis = Basis(mesh, vector_element(order))
    cells = rng.integers(0, mesh.t.shape[1], 300)
    weights = rng.random((3, 300))
    weights /= weights.sum(axis=0)
    x = np.einsum("evn,vn->en", mesh.p[:, mesh.t[:, cells]], weights)
    fast = evaluate_at(basis, x, cells)
    X = basis.mapping.invF(x[:, :, None], tind=cells)
    for k in range(basis.Nbfun):
        field = basis.elem.gbasis(basis.mapping, X, k, tind=cells)[0]
        assert np.array_equal(np.asarray(field)[..., 0], fast.values[k])
        assert np.allclose(field.grad[..., 0], fast.gradients[k], rtol=1e-14, atol=0)

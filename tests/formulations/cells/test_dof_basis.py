"""The displacement basis is scikit-fem's CellBasis on the centroid rule, its basis-function
values computed on first use: every number it gives equals scikit-fem's, to the bit."""

import pickle

import numpy as np
import pytest
from skfem import Basis

from formulations.cells.dof_basis import DofBasis
from formulations.cells.triangle import TRIANGLES
from formulations.elasticity import vector_element
from scenes import get_scene


@pytest.mark.parametrize("order", [1, 2, 3])
def test_the_lazy_basis_equals_scikit_fems(order):
    mesh = get_scene("paper").mesh.refined(2)
    lazy = DofBasis(mesh, vector_element(order), TRIANGLES.centroid_rule)
    assert "basis" not in vars(lazy)  # nothing evaluated yet
    eager = Basis(mesh, vector_element(order), quadrature=TRIANGLES.centroid_rule)
    u = np.random.default_rng(3).normal(size=eager.N)
    for mine, theirs in ((lazy, eager), (pickle.loads(pickle.dumps(lazy)), eager)):
        assert mine.N == theirs.N and np.array_equal(mine.nodal_dofs, theirs.nodal_dofs)
        assert np.array_equal(mine.doflocs, theirs.doflocs) and np.array_equal(mine.dx, theirs.dx)
        a, b = mine.interpolate(u), theirs.interpolate(u)
        assert np.array_equal(np.asarray(a), np.asarray(b)) and np.array_equal(a.grad, b.grad)

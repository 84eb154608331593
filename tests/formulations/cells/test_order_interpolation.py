"""Nodal interpolation between Lagrange orders: a polynomial field of the source's degree is
reproduced exactly by the higher order (nodal interpolation reproduces the polynomials of the
space), and interpolating back returns the field."""

import numpy as np
import pytest
from skfem import MeshTet, MeshTri

from formulations.cells.order_interpolation import interpolation_matrix
from formulations.elasticity import dof_basis

CASES = [(MeshTri.init_symmetric().refined(2), 1), (MeshTri.init_symmetric().refined(2), 2),
         (MeshTet().refined(1), 1)]


def polynomial(basis, p: int) -> np.ndarray:
    """u_c(x) = x_0^p + 2 x_1 - x_0 x_1^(p - 1) + c at every DOF (degree p)."""
    x, u = basis.doflocs, np.zeros(basis.N)
    for c, dofs in enumerate(basis.split_indices()):
        u[dofs] = x[0, dofs] ** p + 2 * x[1, dofs] - x[0, dofs] * x[1, dofs] ** (p - 1) + c
    return u


@pytest.mark.parametrize("mesh,order", CASES)
def test_the_higher_order_reproduces_a_field_of_the_lower(mesh, order):
    low, high = dof_basis(mesh, order), dof_basis(mesh, order + 1)
    up = interpolation_matrix(low, high)
    lifted = up @ polynomial(low, order)
    # round-off of the reference maps only
    np.testing.assert_allclose(lifted, polynomial(high, order), atol=1e-12)
    np.testing.assert_allclose(interpolation_matrix(high, low) @ lifted, polynomial(low, order),
                               atol=1e-12)


def test_bases_on_different_meshes_are_refused():
    with pytest.raises(ValueError, match="same mesh"):
        interpolation_matrix(dof_basis(MeshTri(), 1), dof_basis(MeshTri().refined(), 2))

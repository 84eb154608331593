"""Discontinuous P3 on tetrahedra (estimators.guaranteed.lagrange_tet)."""

import numpy as np

from estimators.guaranteed.lagrange_tet import ElementTetDGP3


def test_the_basis_is_nodal_and_interpolates_cubics_exactly():
    element = ElementTetDGP3()
    nodes = element.doflocs.T
    values = np.array([element.lbasis(nodes, i)[0] for i in range(20)])
    np.testing.assert_allclose(values, np.eye(20), atol=1e-12)
    rng = np.random.default_rng(0)
    c = rng.standard_normal(5)

    def cubic(x):  # a cubic with every kind of term
        return c[0] + c[1] * x[0] * x[1] * x[2] + c[2] * x[1] ** 3 + c[3] * x[0] ** 2 * x[2] + c[4]

    X = rng.uniform(0, 0.3, size=(3, 7))
    interpolated = sum(cubic(nodes[:, i]) * element.lbasis(X, i)[0] for i in range(20))
    np.testing.assert_allclose(interpolated, cubic(X), rtol=1e-12)


def test_the_gradients_are_those_of_the_values():
    """Central differences, step 1e-5: agreement to 1e-8."""
    element = ElementTetDGP3()
    X = np.random.default_rng(1).uniform(0, 0.3, size=(3, 4))
    step = 1e-5
    for i in (0, 7, 19):
        _, grad = element.lbasis(X, i)
        for d in range(3):
            e = np.zeros((3, 1))
            e[d] = step
            fd = (element.lbasis(X + e, i)[0] - element.lbasis(X - e, i)[0]) / (2 * step)
            np.testing.assert_allclose(grad[d], fd, atol=1e-8)

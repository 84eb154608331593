"""Body loads on quadrilaterals: a smooth force keeps the cells' own rule, a force that jumps
inside cells is integrated on split sub-squares (the sum of a component's load is int f, by
the partition of unity, and known in closed form here)."""

import numpy as np
import pytest
from skfem import Basis, ElementQuad1, ElementQuad2, ElementVector, LinearForm, MeshQuad, asm
from skfem.helpers import dot

from formulations.cells.quad_load import quad_body_load


def plain(force, basis):
    @LinearForm
    def form(v, w):
        return dot(force(w.x), v)

    return asm(form, basis)


@pytest.fixture(params=[ElementQuad1, ElementQuad2])
def basis(request):
    mesh = MeshQuad.init_tensor(np.linspace(-1, 1, 8), np.linspace(0, 1, 5))
    return Basis(mesh, ElementVector(request.param()), intorder=5)


def test_a_smooth_force_keeps_the_cells_rule(basis):
    def smooth(x):
        return np.array([np.sin(x[0]) + 0 * x[1], x[0] * x[1]])

    assert np.array_equal(quad_body_load(smooth, basis), plain(smooth, basis))


def test_a_force_that_jumps_inside_cells_is_integrated_on_sub_squares(basis):
    def jumps(x):  # 1 left of x = 0.3 (a line through cells), 2 inside the circle r^2 < 1/2
        return np.array([np.where(x[0] < 0.3, 1.0, 0.0) + 0 * x[1],
                         np.where(x[0] ** 2 + x[1] ** 2 < 0.5, 2.0, 0.0)])

    x_dofs = np.zeros(basis.N, dtype=bool)
    x_dofs[basis.element_dofs[0::2].ravel()] = True
    exact = np.array([1.3, np.pi / 2])  # int f_x = |{x < 0.3}|, int f_y = 2 |quarter disc|
    refined, cell_rule = quad_body_load(jumps, basis), plain(jumps, basis)
    error = np.abs([refined[x_dofs].sum(), refined[~x_dofs].sum()] - exact)
    before = np.abs([cell_rule[x_dofs].sum(), cell_rule[~x_dofs].sum()] - exact)
    # five splits: the error along the jump shrinks about 2^5 = 32 times (measured 45 and 210)
    assert np.all(error < before / 20) and error.max() < 2e-3

"""Nested iteration of the displacement: the previous level's u_h at the new level's nodes, the
first iterate of an iterative solve (docs/theory.md, 18.3)."""

from __future__ import annotations

import numpy as np

from bench.measure.fields import locator_for
from formulations.hat_loads import simplex_mesh


def values_at(basis, u: np.ndarray, x: np.ndarray, cells: np.ndarray) -> np.ndarray:
    """The vector field u of ``basis`` at points x (d, n) in ``cells``, (d, n) (scikit-fem's
    ``probes`` with the cells given, its finder being quadratic in the points)."""
    d, n = x.shape
    pts = basis.mapping.invF(x[:, :, np.newaxis], tind=cells)
    values = np.zeros((d, n))
    for k in range(basis.Nbfun):
        phi = np.asarray(basis.elem.gbasis(basis.mapping, pts, k, tind=cells)[0])  # (d, n, 1)
        values += phi[:, :, 0] * u[basis.element_dofs[k, cells]][None, :]
    return values


def initial_displacement(previous, disc) -> np.ndarray | None:
    """The previous solution's u_h interpolated at the unknowns of ``disc`` (a
    ``Discretisation``): the start of an iterative solve. None where the cells are not a
    conforming simplicial mesh on both levels, or the previous level failed."""
    if previous is None or not previous.ok or not (
            simplex_mesh(disc.elasticity) and simplex_mesh(previous.elasticity)):
        return None
    new = disc.elasticity
    d = new.mesh.dim()
    x = new.basis.doflocs[:, new.free]
    cells = locator_for(previous.elasticity.mesh).find(x)
    values = values_at(previous.elasticity.basis, previous.u, x, cells)
    return values[new.free % d, np.arange(new.free.size)]

"""The displacement basis an ``Elasticity`` carries: scikit-fem's DOF numbering, element maps
and element on the one-point centroid rule, with the values of its basis functions evaluated
on first use.

Nothing integrates with this basis (each integral builds the basis of its own rule, and the
stiffness matrix of order 1 and 2 is written in closed form): what the solvers, estimators and
errors take from it is the numbering (``nodal_dofs``, ``get_dofs``, ``N``), the element and the
mesh's map. scikit-fem's ``CellBasis`` evaluates every basis function at the rule's points on
every element when it is built; for the vector P1 element on 5 x 10^5 triangles that alone is
about 0.5 s, a fifth of the whole assembly, for values that only ``element_stress`` reads.
"""

from __future__ import annotations

import functools

import numpy as np
from skfem import CellBasis, MeshTri
from skfem.element import Element


class DofBasis(CellBasis):
    """A ``CellBasis`` on the centroid rule of its cells (points (d, 1), weight) whose
    ``basis`` (the basis functions' values and gradients there) is computed when first asked
    for; otherwise scikit-fem's own."""

    def __init__(self, mesh: MeshTri, elem: Element, centroid_rule: tuple):
        d = mesh.dim()
        # numbering and maps, no values
        super().__init__(mesh, elem, quadrature=(np.zeros((d, 0)), np.zeros(0)))
        self.__dict__.pop("basis", None)  # scikit-fem's empty list: the property below answers
        self.X, self.W = centroid_rule
        self.dx = np.abs(self.mapping.detDF(self.X)) * np.broadcast_to(self.W, (self.nelems, 1))

    @functools.cached_property
    def basis(self) -> list:
        return [self.elem.gbasis(self.mapping, self.X, j, tind=self.tind)
                for j in range(self.Nbfun)]

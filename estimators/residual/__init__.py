"""The residual family (docs/theory.md, sections 4, 12, 14.1 and 15.3): the seed's residual
estimator ``residual`` (eta_0 plus the contact terms of eq. (8)) and ``nitsche-residual`` (its
volume terms alone, for Nitsche's method), on triangles (``triangles``, where both register),
with the tetrahedral, quadrilateral and hexahedral variants registered the same way
(``register_cell_variant``: ``tetrahedra``, ``quadrilaterals``, ``hexahedra``). Importing this
package registers them all."""

from estimators.residual import (  # noqa: F401  (register themselves)
    hexahedra,
    nitsche,
    quadrilaterals,
    tetrahedra,
    triangles,
)

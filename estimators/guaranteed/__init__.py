"""The guaranteed bounds (docs/theory.md, sections 13 and 17.5; docs/guaranteed.md):
``equilibrated`` (an equilibrated flux by Raviart-Thomas patch problems, with the contact and
friction terms, on triangles and, as its tetrahedral variant ``equilibrated_3d``, on
tetrahedra) and ``equilibrated-local`` (every constant proved, on triangles), and every module
only they use: patches and their classes, Raviart-Thomas elements, symmetrisation, Korn and
trace constants, contact extensions. Importing this package registers the bounds."""

from estimators.guaranteed import (  # noqa: F401  (register themselves)
    equilibrated,
    equilibrated_3d,
    equilibrated_local,
)

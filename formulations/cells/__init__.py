"""Cell families (``formulations.cells.base``): importing this package registers every family
module listed below; adding a family is one new module and one import line here."""

from formulations.cells import hexahedron, quadrilateral, tetrahedron, triangle  # noqa: F401
from formulations.cells.base import (
    CELL_FAMILIES,
    DEFAULT_CELL,
    CellFamily,
    cell_names,
    check_cell,
    family_for,
    family_of,
)

__all__ = ["CELL_FAMILIES", "DEFAULT_CELL", "CellFamily", "cell_names", "check_cell",
           "family_for", "family_of"]

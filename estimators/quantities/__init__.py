"""Quantities of interest (docs/theory.md, 20.1): importing the package registers each one,
one module and one import line per quantity."""

from estimators.quantities import (  # noqa: F401  (register themselves)
    contact_force,
    contact_zone,
    mean_pressure,
    peak_pressure,
    point_displacement,
)
from estimators.quantities.base import (
    DEFAULT_QUANTITY,
    Quantity,
    get_quantity,
    quantity_descriptions,
    quantity_names,
    register_quantity,
)

__all__ = ["DEFAULT_QUANTITY", "Quantity", "get_quantity", "quantity_descriptions",
           "quantity_names", "register_quantity"]

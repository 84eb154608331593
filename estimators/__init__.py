"""Estimators: how the error of a discrete solution is estimated (docs/theory.md, section 4).

Importing this package registers every estimator: ``averaging`` here, the residual family
(``estimators.residual``) and the guaranteed bounds (``estimators.guaranteed``), each a package
whose ``__init__`` imports its estimators. Adding an estimator is one new module with a
``@register_estimator`` ``estimate(scene, solution)`` function and one import line here (or in
its family's ``__init__``).
"""

from estimators import (  # noqa: F401  (register themselves)
    averaging,
    guaranteed,
    residual,
)
from estimators.base import (
    Estimate,
    estimator_descriptions,
    estimator_names,
    get_estimator,
    guaranteed_estimators,
    register_estimator,
)

__all__ = ["Estimate", "estimator_descriptions", "estimator_names", "get_estimator",
           "guaranteed_estimators", "register_estimator"]

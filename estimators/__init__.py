"""Estimators: how the error of a discrete solution is estimated (docs/theory.md, section 4).

Importing this package registers every estimator module listed below; adding an estimator is one
new module with a ``@register_estimator`` ``estimate(scene, solution)`` function and one import
line here.
"""

from estimators import (  # noqa: F401  (register themselves)
    averaging,
    equilibrated,
    equilibrated_3d,
    equilibrated_local,
    nitsche_residual,
    quad_residual,
    residual,
    residual_3d,
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

"""Formulations: how a scene is discretised and solved (docs/theory.md, section 3).

Importing this package registers every formulation module listed below; adding a formulation is
one new module with a ``@register_formulation`` ``discretise`` function and one import line here.
"""

from formulations import mixed, nitsche, penalty, vi  # noqa: F401  (register themselves)
from formulations.base import (
    STATUS_FAILED,
    STATUS_INACCURATE,
    STATUS_OK,
    STATUS_SKIPPED,
    ContactQP,
    DiscreteSolution,
    QPSolution,
    Residuals,
    SolverDiagnostics,
)
from formulations.discretisation import Discretisation, solve
from formulations.registry import (
    formulation_descriptions,
    formulation_names,
    get_formulation,
    register_formulation,
)
from formulations.solvers import get_solver, solver_descriptions, solver_names

__all__ = ["STATUS_FAILED", "STATUS_INACCURATE", "STATUS_OK", "STATUS_SKIPPED", "ContactQP",
           "DiscreteSolution", "Discretisation", "QPSolution", "Residuals", "SolverDiagnostics",
           "formulation_descriptions", "formulation_names", "get_formulation", "get_solver",
           "register_formulation", "solve", "solver_descriptions", "solver_names"]

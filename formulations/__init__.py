"""Formulations: how a scene is discretised and solved (docs/theory.md, section 3).

The rooms: ``methods/`` (the four formulations, one module each), ``cells/`` (the cell families
and their element kernels: stiffness, loads, point evaluation, hanging-node constraints),
``contact/`` (the contact boundary's kinds), ``friction/`` (each method's friction companion and
the friction state) and ``solvers/`` (the QP and system solvers, the sparse back-ends); here the
shared discrete types, assembly, the discretisation and its diagnostics. Importing this package
registers every method listed in ``formulations.methods``; adding a formulation is one new module
there with a ``@register_formulation`` ``discretise`` function and one import line in its
``__init__``.
"""

from formulations import methods  # noqa: F401  (registers the formulations)
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

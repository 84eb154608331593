"""Solvers for the discrete contact problems; importing registers each module listed here."""

from formulations.solvers import active_set, reference, semismooth_newton  # noqa: F401
from formulations.solvers.registry import (
    FAST_SOLVER,
    REFERENCE_SOLVER,
    get_solver,
    get_system_solver,
    register_solver,
    register_system_solver,
    solver_descriptions,
    solver_names,
)

__all__ = ["FAST_SOLVER", "REFERENCE_SOLVER", "get_solver", "get_system_solver",
           "register_solver", "register_system_solver", "solver_descriptions", "solver_names"]

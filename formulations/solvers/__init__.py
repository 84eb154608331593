"""Solvers for the discrete contact problems; importing registers each module listed here."""

from formulations.solvers import active_set, reference  # noqa: F401  (registers them)
from formulations.solvers.registry import (
    get_solver,
    register_solver,
    solver_descriptions,
    solver_names,
)

__all__ = ["get_solver", "register_solver", "solver_descriptions", "solver_names"]

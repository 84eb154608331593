"""Solver registry: name -> ``solve(qp: ContactQP, warm_start=None) -> QPSolution``."""

from scenes.registry import Registry

SOLVERS = Registry("solver")
register_solver = SOLVERS.register
solver_names = SOLVERS.names
solver_descriptions = SOLVERS.descriptions
get_solver = SOLVERS.get

"""Solver registries. A solver name may stand for two methods of one idea:

* ``SOLVERS``: name -> ``solve(qp: ContactQP, warm_start=None, backend=None) -> QPSolution``
  for the formulations that are a QP (mixed, penalty, vi; nitsche with theta = 1);
* ``SYSTEM_SOLVERS``: name -> ``solve(system: SemismoothSystem, warm_start=None,
  backend=None) -> QPSolution`` for those that are a piecewise linear equation (nitsche).

``formulations.discretisation.solve`` picks the method for the discretisation's problem: the
system when the formulation has one and the name has a system method, else the QP. A name with
no method for what a formulation offers is a ``skipped`` combination (``why_unsolvable``).
"""

from scenes.registry import Registry

# the two roles the suite gives solvers: the judge of correctness, and the fast solver every
# sequence, scaling run and hard case times (their names, used wherever a role is meant)
REFERENCE_SOLVER = "reference"
FAST_SOLVER = "active-set"

SOLVERS = Registry("solver")
SYSTEM_SOLVERS = Registry("solver")
register_solver = SOLVERS.register
register_system_solver = SYSTEM_SOLVERS.register
get_solver = SOLVERS.get
get_system_solver = SYSTEM_SOLVERS.get


def solver_names() -> list[str]:
    return sorted(set(SOLVERS.names()) | set(SYSTEM_SOLVERS.names()))


def solver_descriptions() -> dict[str, str]:
    qp, system = SOLVERS.descriptions(), SYSTEM_SOLVERS.descriptions()
    return {name: "; ".join(text for text in (qp.get(name), system.get(name) and
                                              f"for semismooth systems: {system[name]}")
                            if text)
            for name in solver_names()}

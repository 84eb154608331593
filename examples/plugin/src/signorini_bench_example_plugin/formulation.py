"""``penalty-soft``: the suite's primal penalty with a hundred times its default eps_0, to see
what a soft penalty costs in penetration and in accuracy."""

from formulations import register_formulation
from formulations.methods.penalty import discretise as penalty

EPSILON_0 = 0.1


@register_formulation("penalty-soft", f"example plugin: the primal penalty with eps_0 = "
                                      f"{EPSILON_0} (soft: more penetration)")
def discretise(scene, mesh, order: int = 1):
    return penalty(scene, mesh, epsilon_0=EPSILON_0, order=order)

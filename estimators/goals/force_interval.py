"""A guaranteed interval for the contact force from a guaranteed energy bound (docs/theory.md,
20.6). For any psi in V (psi = 0 on Gamma_D) with psi.n = 1 on Gamma_C, the equation gives
F = (lambda, 1) = L(psi) - a(u, psi), so with c = L(psi) - a(u_h, psi)

    |F - c| = |a(u - u_h, psi)| <= ||u - u_h|| ||psi|| <= eta ||psi||,

eta a guaranteed bound of the energy error (``Estimate.guaranteed``). psi is taken in the
discrete space with the least energy (the body's response to a unit normal displacement of all
of Gamma_C, ``held_normal``): the narrowest interval of this form there. The interval holds
whatever the contact set, the formulation or the solver's stop; it needs every node of Gamma_C
to be free (psi.n = 1 cannot hold at a clamped node) and takes L(psi) from the load rule.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from estimators.goals.dual import held_normal, node_dofs


@dataclass(frozen=True)
class ForceInterval:
    """[centre - half_width, centre + half_width] holds the contact force."""

    centre: float
    half_width: float
    psi_norm: float  # ||psi|| = a(psi, psi)^1/2, what multiplies the energy bound

    @property
    def lower(self) -> float:
        return self.centre - self.half_width

    @property
    def upper(self) -> float:
        return self.centre + self.half_width


def why_no_interval(solution) -> str | None:
    """Why the interval cannot be had on ``solution``'s mesh (a clamped or hanging node on
    Gamma_C), or None."""
    nodes = solution.trace.nodes(solution.elasticity.order)
    _, own = node_dofs(solution.elasticity, solution.trace, nodes)
    if not own.all():
        return (f"{int((~own).sum())} nodes of Gamma_C are clamped or hanging: psi.n = 1 "
                "cannot hold there")
    return None


def force_interval(solution, energy_bound: float, backend: str | None = None
                   ) -> ForceInterval:
    """The interval of the contact force from a guaranteed bound ``energy_bound`` of
    ||u - u_h|| (ValueError where ``why_no_interval`` says it cannot be had)."""
    why = why_no_interval(solution)
    if why is not None:
        raise ValueError(f"no guaranteed force interval: {why}")
    elasticity, trace = solution.elasticity, solution.trace
    nodes = trace.nodes(elasticity.order)
    columns, _ = node_dofs(elasticity, trace, nodes)
    psi_free, _ = held_normal(elasticity, columns, nodes.normal, np.ones(columns.shape[1]),
                              np.zeros(elasticity.ndofs), backend)
    psi = elasticity.expand(psi_free)
    norm = float(np.sqrt(psi_free @ (elasticity.K_free @ psi_free)))
    centre = float(elasticity.F @ psi - psi @ (elasticity.K @ solution.u))
    return ForceInterval(centre=centre, half_width=float(energy_bound) * norm, psi_norm=norm)

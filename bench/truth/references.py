"""Overkill references for scenes without an exact solution, cached on disk.

A reference is the last level of an adaptive sequence (mixed method, active-set solver,
residual estimator, Doerfler 0.5) run to ``max_dofs``. Its own energy-norm error is estimated
from its last two levels: if the error decays like N^(-1/2) (the adaptive rate, measured) and
the levels are nearly orthogonal in the energy norm, e_L = ||u_L - u_(L-1)|| / sqrt(N_L/N_(L-1)
- 1). It is a model, not a bound; ``reference_too_coarse`` flags rows whose error is within 10x.

The cache (``bench.truth.cache``) is keyed by a hash of everything that determines the
reference: scene name and parameters, formulation, solver, estimator, marking, DOF budget and
``ASSEMBLY_VERSION`` (bump it when the assembly or a formulation changes).
"""

from __future__ import annotations

import functools
import hashlib
import json
from dataclasses import dataclass

import numpy as np
from skfem import MeshTri

from bench.measure.contact import contact_zone
from bench.measure.discretisation_error import Errors, errors_from
from bench.measure.nonnested import P1Field, energy_error_on
from bench.sequence.loop import LoopConfig, run_sequence
from formulations import STATUS_OK, DiscreteSolution

ASSEMBLY_VERSION = 2  # 2: greedy multiplier segments, contact grading closure
RECIPE = {"formulation": "mixed", "solver": "active-set", "estimator": "residual",
          "strategy": "adaptive", "marking": "doerfler", "theta": 0.5}


@dataclass(frozen=True, eq=False)
class Reference:
    key: str
    mesh: MeshTri
    u_nodal: np.ndarray
    lame: tuple[float, float]
    pressure_s: np.ndarray  # contact coordinates and reference pressure there (dense samples)
    pressure_values: np.ndarray
    ndofs: int
    energy: float
    contact_force: float
    zone: tuple[float, float]
    estimated_error: float

    def pressure(self, s: np.ndarray) -> np.ndarray:
        return np.interp(s, self.pressure_s, self.pressure_values)

    @functools.cached_property
    def field(self) -> P1Field:
        return P1Field.from_nodal(self.mesh, self.u_nodal)

    def errors(self, solution: DiscreteSolution) -> Errors:
        return errors_from(energy_error_on(self.field, self.lame, solution), solution,
                           self.pressure, self.zone)

    def summary(self) -> dict:
        return {"ndofs": self.ndofs, "energy": self.energy, "contact_force": self.contact_force,
                "contact_zone_start": self.zone[0], "contact_zone_end": self.zone[1],
                "estimated_error": self.estimated_error, "key": self.key}


def reference_key(scene, max_dofs: int) -> str:
    recipe = {"scene": scene.name, "parameters": scene.parameters, "max_dofs": max_dofs,
              "assembly_version": ASSEMBLY_VERSION, **RECIPE}
    text = json.dumps(recipe, sort_keys=True, default=str)
    return f"{scene.name}-{max_dofs}-{hashlib.sha256(text.encode()).hexdigest()[:16]}"


def _sampled_pressure(solution: DiscreteSolution):
    t = np.linspace(0.0, 1.0, 9)
    return solution.trace.coordinates_at(t).ravel(), solution.pressure(t).ravel()


class TruthError(ValueError):
    """A reference that cannot be built or cannot be trusted for the runs it would judge."""


def build_reference(scene, max_dofs: int) -> Reference:
    config = LoopConfig(strategy="adaptive", max_dofs=max_dofs, marking=RECIPE["marking"],
                        theta=RECIPE["theta"], diagnostics=False)
    previous, last = None, None
    for result in run_sequence(scene, RECIPE["formulation"], RECIPE["solver"],
                               RECIPE["estimator"], config):
        if result.row.status != STATUS_OK:
            raise TruthError(f"reference for scene {scene.name!r}: level {result.row.level} "
                             f"failed: {result.row.reason}")
        previous, last = last, result
    if previous is None:
        raise TruthError(f"reference_dofs={max_dofs} leaves the {scene.name!r} reference one "
                         f"level ({last.row.ndofs} DOFs): its own error cannot be estimated; "
                         "give a budget of at least ten times the runs' --max-dofs")
    sol = last.solution
    u_nodal = sol.elasticity.nodal(sol.u)
    difference = energy_error_on(P1Field.from_nodal(sol.elasticity.mesh, u_nodal),
                                 sol.elasticity.lame, previous.solution)
    ratio = last.row.ndofs / previous.row.ndofs
    s, values = _sampled_pressure(sol)
    return Reference(key=reference_key(scene, max_dofs), mesh=sol.elasticity.mesh,
                     u_nodal=u_nodal, lame=sol.elasticity.lame, pressure_s=s,
                     pressure_values=values, ndofs=last.row.ndofs, energy=sol.energy,
                     contact_force=sol.contact_force(), zone=contact_zone(sol),
                     estimated_error=float(difference / np.sqrt(max(ratio - 1.0, 1e-12))))

"""Overkill references for scenes without an exact solution, cached on disk
(docs/theory.md, section 6.3).

A reference is the last level of an adaptive sequence of a ``Recipe``: by default the mixed
method in P3 (``PRIMARY``), which on the singular paper scene converges like N^(-3/2) against
N^(-1/2) for P1, so that a few hundred thousand DOFs are far sharper than any P1 run it judges.
Its own energy-norm error is estimated from the differences between its last levels
(``bench.truth.error_bar``); ``reference_too_coarse`` flags rows whose error is not at least
1/TOO_COARSE times larger. A second recipe (``CROSSCHECK``, P2) checks the first
(``bench.truth.crosscheck``). On tetrahedra there is no P3, and the mixed method's multiplier
is piecewise constant whatever p (docs/theory.md, section 14.7), so the references are P2: the
variational inequality first, Nitsche's method as its cross-check
(``recipes_for``; docs/theory.md, section 14.6). The VI comes first because its condensed
solve couples one DOF per contact node; Nitsche's couples every DOF of the tetrahedra on
Gamma_C, whose dense Schur block outgrows the memory near 1.5e5 P2 DOFs.

The cache (``bench.truth.cache``) is keyed by a hash of everything that determines the
reference: scene name and parameters, recipe, DOF budget and ``ASSEMBLY_VERSION`` (bump it when
the assembly or a formulation changes).
"""

from __future__ import annotations

import functools
import hashlib
import json
import sys
import time
from dataclasses import asdict, dataclass

import numpy as np
from scipy.interpolate import LinearNDInterpolator
from skfem import MeshTet, MeshTri

from bench.measure.contact import STATUS_UNRESOLVED, contact_zone
from bench.measure.discretisation_error import Errors, errors_from
from bench.measure.fields import GradientField
from bench.measure.nonnested import energy_difference
from bench.measure.quad_fields import gradient_field_of
from bench.sequence.loop import LoopConfig, run_sequence
from bench.truth.error_bar import error_bar
from formulations import STATUS_OK, DiscreteSolution
from formulations.solvers.backends import FactorisationError
from formulations.solvers.registry import FAST_SOLVER

ASSEMBLY_VERSION = 3  # 3: P_p references, error bar with a fitted rate


@dataclass(frozen=True)
class Recipe:
    """How a reference is built: an adaptive sequence of one formulation at one order."""

    name: str
    formulation: str
    order: int
    solver: str = FAST_SOLVER
    estimator: str = "residual"
    marking: str = "doerfler"
    theta: float = 0.5
    budget_factor: float = 1.0  # the DOF budget is this times the reference's


# the P2 cross-check gets twice the budget: its energy must agree with P3's to 1e-7, and its
# energy error, ||e||^2 / ||u||^2, is 1.1e-7 on hertz at the same budget (3.3e-4 relative)
RECIPES = {r.name: r for r in (Recipe("mixed-p3", "mixed", 3),
                               Recipe("mixed-p2", "mixed", 2, budget_factor=2.0),
                               Recipe("vi-p2", "vi", 2), Recipe("nitsche-p2", "nitsche", 2))}
PRIMARY, CROSSCHECK = "mixed-p3", "mixed-p2"
RECIPES_BY_DIM = {2: (PRIMARY, CROSSCHECK), 3: ("vi-p2", "nitsche-p2")}


def recipes_for(scene) -> tuple[str, str]:
    """The primary and the cross-check recipe of a scene's dimension."""
    return RECIPES_BY_DIM[scene.dim]


@dataclass(frozen=True, eq=False)
class Reference:
    key: str
    recipe: str
    order: int
    mesh: MeshTri | MeshTet
    u: np.ndarray  # the DOF vector of vector P_order on ``mesh`` (scikit-fem's numbering)
    lame: tuple[float, float]
    pressure_s: np.ndarray  # contact coordinates ((2, n) in 3D) and reference pressure there
    pressure_values: np.ndarray
    ndofs: int
    energy: float
    norm: float  # ||u_ref|| = a(u_ref, u_ref)^(1/2), the scale of relative errors
    contact_force: float
    zone: tuple[float, float]
    estimated_error: float
    rate: float  # the fitted decay rate of the error bar (N^-rate)
    build_seconds: float

    def pressure(self, s: np.ndarray) -> np.ndarray:
        """The reference pressure at contact coordinates ``s``: linear between the samples
        (in 3D on their Delaunay triangulation, 0 outside their hull)."""
        if self.pressure_s.ndim == 2:
            return self._surface_pressure(*s)
        return np.interp(s, self.pressure_s, self.pressure_values)

    @functools.cached_property
    def _surface_pressure(self) -> LinearNDInterpolator:
        return LinearNDInterpolator(self.pressure_s.T, self.pressure_values, fill_value=0.0)

    @property
    def peak_pressure(self) -> float:
        return float(self.pressure_values.max()) if self.pressure_values.size else 0.0

    @functools.cached_property
    def field(self) -> GradientField:
        return GradientField.from_dofs(self.mesh, self.order, self.u)

    def errors(self, solution: DiscreteSolution) -> Errors:
        judged = gradient_field_of(solution.elasticity.basis, solution.u)
        return errors_from(energy_difference(judged, self.field, self.lame), solution,
                           self.pressure, self.zone)

    def summary(self) -> dict:
        return {"recipe": self.recipe, "order": self.order, "ndofs": self.ndofs,
                "energy": self.energy, "energy_norm": self.norm,
                "relative_estimated_error": self.estimated_error / self.norm,
                "contact_force": self.contact_force,
                "contact_zone_start": self.zone[0], "contact_zone_end": self.zone[1],
                "peak_pressure": self.peak_pressure, "estimated_error": self.estimated_error,
                "error_rate": self.rate, "build_seconds": self.build_seconds, "key": self.key}


def reference_key(scene, max_dofs: int, recipe: str | None = None) -> str:
    recipe = recipes_for(scene)[0] if recipe is None else recipe
    spec = {"scene": scene.name, "parameters": scene.parameters, "max_dofs": max_dofs,
            "assembly_version": ASSEMBLY_VERSION, **asdict(RECIPES[recipe])}
    text = json.dumps(spec, sort_keys=True, default=str)
    return f"{scene.name}-{recipe}-{max_dofs}-{hashlib.sha256(text.encode()).hexdigest()[:16]}"


def _sampled_pressure(solution: DiscreteSolution):
    """A reference's pressure: contact coordinates and values, from the contact boundary."""
    return solution.trace.pressure_samples(solution)


class TruthError(ValueError):
    """A reference that cannot be built or cannot be trusted for the runs it would judge."""


class LevelProgress:
    """Progress of a long sequence on standard error: one line rewritten in place on a
    terminal (level, DOFs, elapsed seconds), nothing otherwise (its caller says when it
    starts and ends)."""

    def __init__(self, title: str, max_dofs: int, stream=None):
        self.stream = sys.stderr if stream is None else stream
        self.live = self.stream.isatty()
        self.title, self.max_dofs, self.start = title, max_dofs, time.perf_counter()

    def __call__(self, level: int, ndofs: int) -> None:
        if not self.live:
            return
        self.stream.write(f"\r[{self.title}] level {level:2d}: {ndofs:9d} DOFs (budget "
                          f"{self.max_dofs}), {time.perf_counter() - self.start:6.1f} s elapsed ")
        self.stream.flush()

    def close(self) -> None:
        if self.live:
            self.stream.write("\n")
            self.stream.flush()


def reference_levels(scene, max_dofs: int, recipe: Recipe):
    """The recipe's adaptive sequence: yields (ndofs, solution, energy-norm difference to the
    level before or None); TruthError if a level fails."""
    config = LoopConfig(strategy="adaptive", order=recipe.order,
                        max_dofs=int(max_dofs * recipe.budget_factor),
                        marking=recipe.marking, theta=recipe.theta, diagnostics=False)
    previous, sequence = None, run_sequence(scene, recipe.formulation, recipe.solver,
                                            recipe.estimator, config)
    while True:
        try:
            result = next(sequence)
        except StopIteration:
            return
        except FactorisationError as error:  # e.g. a dense block too large for the memory
            raise TruthError(f"reference for scene {scene.name!r}: a level beyond the last "
                             f"one built failed: {error}; lower --reference-dofs") from None
        if result.solution is None and result.row.level == 0 and \
                result.row.reason.startswith("budget"):
            raise TruthError(f"reference_dofs={max_dofs} leaves the {scene.name!r} reference "
                             f"not even one level (its starting mesh has {result.row.ndofs} "
                             f"DOFs at P{recipe.order}); give a larger budget")
        if result.row.status not in (STATUS_OK, STATUS_UNRESOLVED):
            raise TruthError(f"reference for scene {scene.name!r}: level {result.row.level} "
                             f"failed: {result.row.reason}")
        sol = result.solution
        field = GradientField.from_solution(sol.elasticity.basis, sol.u)
        # nested levels: the finer field first makes the integral exact
        difference = (None if previous is None
                       else energy_difference(field, previous, sol.elasticity.lame))
        previous = field
        yield result.row, sol, difference


def build_reference(scene, max_dofs: int, recipe: str | None = None) -> Reference:
    recipe = recipes_for(scene)[0] if recipe is None else recipe
    start = time.perf_counter()
    ndofs, differences, sol = [], [], None
    show = LevelProgress(f"reference {scene.name}/{recipe}", max_dofs)
    for row, level_solution, difference in reference_levels(scene, max_dofs,
                                                            RECIPES[recipe]):
        show(len(ndofs), row.ndofs)
        ndofs.append(row.ndofs)
        sol, last = level_solution, row
        if difference is not None:
            differences.append(difference)
    if not differences:
        raise TruthError(f"reference_dofs={max_dofs} leaves the {scene.name!r} reference one "
                         f"level ({ndofs[-1]} DOFs): its own error cannot be estimated; "
                         "give a larger budget")
    show.close()
    if last.status != STATUS_OK:  # a coarse level may miss the contact, the truth may not
        raise TruthError(f"reference for scene {scene.name!r}: its finest level ({last.ndofs} "
                         f"DOFs) has not resolved the contact: {last.reason}; give a larger "
                         "budget")
    bar = error_bar(ndofs, differences)
    s, values = _sampled_pressure(sol)
    return Reference(key=reference_key(scene, max_dofs, recipe), recipe=recipe,
                     order=RECIPES[recipe].order, mesh=sol.elasticity.mesh, u=sol.u,
                     lame=sol.elasticity.lame, pressure_s=s, pressure_values=values,
                     ndofs=ndofs[-1], energy=sol.energy,
                     norm=float(np.sqrt(sol.u @ (sol.elasticity.K @ sol.u))),
                     contact_force=sol.contact_force(),
                     zone=contact_zone(sol), estimated_error=bar.estimated_error,
                     rate=bar.rate, build_seconds=time.perf_counter() - start)

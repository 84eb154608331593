"""What a run measures its errors against: the scene's exact solution, else an overkill
reference (``bench.truth.references``), or nothing. A truth says when it is too coarse to judge
an error: when its own estimated error exceeds TOO_COARSE times that error."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bench.measure.discretisation_error import Errors, exact_errors
from bench.truth.cache import load_or_build
from bench.truth.crosscheck import CrossCheck, cross_check
from bench.truth.references import TruthError, recipes_for

TOO_COARSE = 0.05  # a reference whose own error exceeds 5 % of the measured error is too coarse
# A reference of an order no higher than the runs it judges needs at least this many times the
# DOFs of their finest level: at the adaptive rate N^(-p/2) its own error is then at most
# 10^(-1/2) of that level's, the least for the two to be told apart; a smaller one is refused
# before any run. A reference of higher order converges faster and is judged row by row.
REFERENCE_FACTOR = 10


class _Truth:
    estimated_error: float

    def too_coarse(self, energy_error: float, solution) -> bool:
        return bool(self.estimated_error > TOO_COARSE * energy_error)


@dataclass(frozen=True, eq=False)
class ExactTruth(_Truth):
    scene: object
    estimated_error: float = 0.0
    kind: str = "exact"

    def errors(self, solution) -> Errors:
        return exact_errors(self.scene, solution)


@dataclass(frozen=True, eq=False)
class ReferenceTruth(_Truth):
    reference: object
    crosscheck: CrossCheck | None = None
    kind: str = "reference"

    @property
    def estimated_error(self) -> float:
        return self.reference.estimated_error

    def errors(self, solution) -> Errors:
        return self.reference.errors(solution)

    def too_coarse(self, energy_error: float, solution) -> bool:
        """Also when the judged solution has contact and the reference has none."""
        no_contact = not self.reference.zone[0] == self.reference.zone[0]  # NaN: no zone
        return super().too_coarse(energy_error, solution) or bool(
            no_contact and solution.active_constraints > 0)


def check_reference(reference, scene, judged_max_dofs: int | None, judged_order: int = 1,
                    ) -> None:
    """Refuse a reference that cannot judge runs up to ``judged_max_dofs`` DOFs of order up
    to ``judged_order``."""
    where = f"the {scene.name!r} reference ({reference.ndofs} DOFs)"
    if not (np.isfinite(reference.estimated_error) and reference.estimated_error > 0):
        raise TruthError(f"{where} estimates its own error as {reference.estimated_error:g}: "
                         "it has not shown it is sharper than anything; raise --reference-dofs")
    if (judged_max_dofs is not None and reference.order <= judged_order
            and reference.ndofs < REFERENCE_FACTOR * judged_max_dofs):
        raise TruthError(f"{where} is not {REFERENCE_FACTOR}x finer than the runs it would "
                         f"judge (--max-dofs={judged_max_dofs}); raise --reference-dofs to at "
                         f"least {REFERENCE_FACTOR * judged_max_dofs * 2} or lower --max-dofs")


def truth_for(scene, reference_dofs: int | None, judged_max_dofs: int | None = None,
              judged_order: int = 1, crosscheck: bool = False, cache=None):
    """Exact if the scene has an exact solution; else the cached reference with
    ``reference_dofs`` DOFs (None: no error measurement) from the folder ``cache``
    (``bench.truth.cache.cache_folder``), refused (TruthError) if it cannot judge runs up to
    ``judged_max_dofs`` DOFs of order ``judged_order``; with ``crosscheck`` also the second
    recipe's reference, compared with the first."""
    if scene.exact is not None:
        return ExactTruth(scene)
    if reference_dofs is None:
        return None
    reference = load_or_build(scene, reference_dofs, cache=cache)
    check_reference(reference, scene, judged_max_dofs, judged_order)
    second = recipes_for(scene)[1] if crosscheck else None
    check = (cross_check(reference, load_or_build(scene, reference_dofs, second, cache))
             if crosscheck else None)
    return ReferenceTruth(reference, check)

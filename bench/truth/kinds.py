"""What a run measures its errors against: the scene's exact solution, else an overkill
reference (``bench.truth.references``), or nothing. A truth says when it is too coarse to judge
an error: when its own estimated error exceeds TOO_COARSE times that error."""

from __future__ import annotations

from dataclasses import dataclass

from bench.measure.discretisation_error import Errors, exact_errors
from bench.truth.references import load_or_build

TOO_COARSE = 0.1  # a reference whose own error exceeds 10 % of the measured error is too coarse


class _Truth:
    estimated_error: float

    def too_coarse(self, energy_error: float) -> bool:
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
    kind: str = "reference"

    @property
    def estimated_error(self) -> float:
        return self.reference.estimated_error

    def errors(self, solution) -> Errors:
        return self.reference.errors(solution)


def truth_for(scene, reference_dofs: int | None):
    """Exact if the scene has an exact solution; else the cached reference with
    ``reference_dofs`` DOFs (None: no error measurement)."""
    if scene.exact is not None:
        return ExactTruth(scene)
    if reference_dofs is None:
        return None
    return ReferenceTruth(load_or_build(scene, reference_dofs))

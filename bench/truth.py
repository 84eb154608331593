"""What a run measures its errors against: the scene's exact solution, else an overkill
reference (``bench.references``), or nothing."""

from __future__ import annotations

from dataclasses import dataclass

from bench.errors import Errors, exact_errors
from bench.references import load_or_build


@dataclass(frozen=True, eq=False)
class ExactTruth:
    scene: object
    estimated_error: float = 0.0
    kind: str = "exact"

    def errors(self, solution) -> Errors:
        return exact_errors(self.scene, solution)


@dataclass(frozen=True, eq=False)
class ReferenceTruth:
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

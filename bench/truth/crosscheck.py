"""Two references from independent recipes must agree (docs/theory.md, section 6.3): the
primary (P3) and the cross-check (P2) recipe, on different adaptive meshes, in energy and in
contact force. A reference sharper than 5e-5 in relative energy norm has an energy error of
about (5e-5)^2 relative, so ENERGY_AGREEMENT = 1e-7 leaves room for the cross-check's own
error; the contact force converges more slowly (a boundary functional), hence 1e-6."""

from __future__ import annotations

from dataclasses import asdict, dataclass

from bench.measure.nonnested import energy_difference

ENERGY_AGREEMENT = 1e-7
FORCE_AGREEMENT = 1e-6


@dataclass(frozen=True)
class CrossCheck:
    recipe: str  # the cross-check's recipe
    ndofs: int
    energy_difference: float  # |E_1 - E_2| / |E_1|
    force_difference: float  # |F_1 - F_2| / |F_1|
    energy_norm_difference: float  # ||u_1 - u_2|| / ||u_1||
    passed: bool

    def summary(self) -> dict:
        return asdict(self)


def _relative(a: float, b: float) -> float:
    scale = max(abs(a), abs(b))
    return abs(a - b) / scale if scale > 0 else 0.0


def cross_check(primary, other) -> CrossCheck:
    """Compare reference ``other`` with ``primary`` (``bench.truth.references.Reference``)."""
    energy = _relative(primary.energy, other.energy)
    force = _relative(primary.contact_force, other.contact_force)
    norm = energy_difference(other.field, primary.field, primary.lame)
    return CrossCheck(recipe=other.recipe, ndofs=other.ndofs, energy_difference=energy,
                      force_difference=force, energy_norm_difference=norm / primary.norm,
                      passed=bool(energy <= ENERGY_AGREEMENT and force <= FORCE_AGREEMENT))

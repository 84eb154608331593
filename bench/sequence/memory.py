"""A measured model of a level's peak memory, so that a level that would not fit is refused
before it is built (docs/theory.md, section 7).

The model is linear in the number of unknowns N, per solver route:

    peak [GiB] = base + per_dof * N.

Coefficients are fitted to ``python -m bench scaling`` (peak resident memory of a whole level:
assembly, factorisation, contact solve, estimator; paper scene, mixed method, uniform meshes)
on the 2-core reference machine:

* ``pardiso`` (active-set): 0.23 / 0.52 / 2.58 GiB at 10 512 / 100 800 / 992 640 DOFs; the
  line through the first and the last gives base 0.20 GiB and 2.39e-6 GiB per DOF (2.6 kB),
  0.86 x the middle point (P2 at 992 640 DOFs: 3.25 GiB measured, 3.53 predicted);
* ``cholmod`` (active-set): 0.218 / 0.650 / 4.893 GiB at 10 512 / 100 800 / 992 640 DOFs; the
  line through the last two gives base 0.17 GiB and 4.76e-6 GiB per DOF (5.1 kB), within 5 %
  of all three points;
* ``splu`` (active-set): 0.244 / 0.953 GiB at 10 512 / 100 800 DOFs, the line through them
  (7.85e-6 GiB per DOF); beyond 1e5 unmeasured, so SuperLU's superlinear fill may exceed it;
* ``reference`` (Clarabel): running after the cholmod route in the same process it never raised
  the peak at 1e5 or 1e6, so the cholmod line is used as its bound.

Formulations differ by a few slack unknowns per contact point, which the model ignores.

Higher order: a P_p DOF couples to more DOFs (stiffness nonzeros per row 12 / 22 / 33 for
p = 1 / 2 / 3; CHOLMOD's factor about the same per DOF), so the per-DOF slope is scaled by
ORDER_FACTOR, measured with ``python -m bench scaling --sizes 1e4,1e5 --order 1,2,3`` (cholmod):
peak 0.83 GiB at 100 800 P2 DOFs (1.4 x the P1 slope) and 0.62 GiB at 56 784 P3 DOFs (1.7 x).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

MARGIN = 0.1  # keep this fraction of the available memory (at least MIN_MARGIN_GIB) free
MIN_MARGIN_GIB = 1.0


@dataclass(frozen=True)
class MemoryLine:
    base_gib: float
    per_dof_gib: float

    def peak_gib(self, ndofs: int) -> float:
        return self.base_gib + self.per_dof_gib * ndofs


CHOLMOD = MemoryLine(0.1713, 4.754e-6)
MODEL = {"pardiso": MemoryLine(0.2048, 2.393e-6), "cholmod": CHOLMOD,
         "splu": MemoryLine(0.1612, 7.851e-6), "reference": CHOLMOD}
ORDER_FACTOR = {1: 1.0, 2: 1.4, 3: 1.7}  # per-DOF memory of P_p relative to P1 (docstring)


def route(solver: str, backend: str) -> str:
    return "reference" if solver == "reference" else backend


def predict_peak_gib(ndofs: int, solver: str, backend: str, order: int = 1) -> float:
    """The predicted peak memory of a level with ``ndofs`` unknowns of order ``order`` (GiB);
    a back-end without a measured line gets the steepest one (a bound, not a fit)."""
    steepest = max(MODEL.values(), key=lambda line: line.per_dof_gib)
    line = MODEL.get(route(solver, backend), steepest)
    return line.base_gib + ORDER_FACTOR[order] * line.per_dof_gib * ndofs


def available_gib(meminfo: str | Path = "/proc/meminfo") -> float:
    """Memory a run may use: the kernel's MemAvailable minus a margin (GiB); inf where the
    kernel does not say."""
    try:
        fields = dict(line.split(":", 1) for line in Path(meminfo).read_text().splitlines()
                      if ":" in line)
        kib = float(fields["MemAvailable"].split()[0])
    except (OSError, KeyError, ValueError):
        return float("inf")
    gib = kib / 2**20
    return max(gib - max(MARGIN * gib, MIN_MARGIN_GIB), 0.0)

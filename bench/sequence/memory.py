"""A measured model of a level's peak memory, so that a level that would not fit is refused
before it is built (docs/theory.md, section 7).

The model is linear in the number of unknowns N, per solver route:

    peak [GiB] = base + per_dof * N.

Each sparse back-end carries its line (``Backend.memory_gib``, with the measurements beside it
in its own module), fitted to ``python -m bench scaling`` (peak resident memory of a whole
level: assembly, factorisation, contact solve, estimator; paper scene, mixed method, uniform
meshes) on the 2-core reference machine. ``reference`` (Clarabel), running after the cholmod
route in the same process, never raised the peak at 1e5 or 1e6, so the cholmod line
(REFERENCE_BOUND) bounds it. A back-end without a line gets the steepest measured one.

Iterative back-ends (``amg``) factorise nothing: their memory is linear in N in 3D as in 2D,
and a level whose direct factorisation would not fit is solved by the first iterative back-end
that does (``iterative_route``; the row's reason says so) instead of refused.

Formulations differ by a few slack unknowns per contact point, which the model ignores.

A condensing back-end (pardiso, cholmod) also forms a dense Schur block over the contact DOFs,
DENSE_COPIES arrays of m^2 doubles, which grows with the square of the contact zone and which
no line in N sees (27 265 contact DOFs of a 3D P2 level: 16.6 GiB). The assembled level knows
m (``formulations.discretisation.dense_block_size``), and ``dense_block_route`` moves a level
whose block does not fit beside the rest to an iterative back-end, within the memory the
level's route was chosen in before its assembly.

Higher order: a P_p DOF couples to more DOFs (stiffness nonzeros per row 12 / 22 / 33 for
p = 1 / 2 / 3; CHOLMOD's factor about the same per DOF), so the per-DOF slope is scaled by
ORDER_FACTOR, measured with ``python -m bench scaling --sizes 1e4,1e5 --order 1,2,3`` (cholmod):
peak 0.83 GiB at 100 800 P2 DOFs (1.4 x the P1 slope) and 0.62 GiB at 56 784 P3 DOFs (1.7 x).

Tetrahedra: a 3D factor fills faster than N (nested dissection: N^(4/3) nonzeros), so the 3D
slope is DIM3_FACTOR times the 2D one at DIM3_AT DOFs and grows like N^(1/3) from there
(bounded below by the factor itself). Measured on ``free-boundary-3d`` (vi, active-set,
pardiso, one uniform level in a fresh process): peak 1.48 GiB at 104 544 P1 DOFs (5.1 x the
2D slope) and 1.69 GiB at 104 544 P2 DOFs (4.2 x the 2D P2 slope). With MKL 2026.2 the same
PARDISO factorisations take more: ``bench scaling --dim 3`` (paper-3d, vi) peaks at 2.06 /
16.19 GiB at 104 544 / 545 832 P1 DOFs (7.4 and 7.1 x the 2D slope, the latter after the
N^(1/3) growth), against 1.31 / 9.12 GiB with the MKL of the first table; DIM3_FACTOR = 7.4
bounds both.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from formulations.solvers.backends import DENSE_COPIES, check_backend
from formulations.solvers.backends.base import REGISTRY as BACKENDS
from formulations.solvers.registry import REFERENCE_SOLVER

MARGIN = 0.1  # keep this fraction of the available memory (at least MIN_MARGIN_GIB) free
MIN_MARGIN_GIB = 1.0


@dataclass(frozen=True)
class MemoryLine:
    base_gib: float
    per_dof_gib: float

    def peak_gib(self, ndofs: int) -> float:
        return self.base_gib + self.per_dof_gib * ndofs


REFERENCE_BOUND = "cholmod"  # the back-end whose measured line bounds the reference (docstring)
ORDER_FACTOR = {1: 1.0, 2: 1.4, 3: 1.7}  # per-DOF memory of P_p relative to P1 (docstring)
# 3D: per-DOF memory relative to 2D at DIM3_AT DOFs (docstring), then growing like N^(1/3)
DIM3_FACTOR, DIM3_AT = 7.4, 1.05e5
# per dimension: the per-DOF factor against the measured 2D lines, from how many DOFs it grows,
# and the power of N it grows with
FILL = {2: (1.0, 1.0, 0.0), 3: (DIM3_FACTOR, DIM3_AT, 1 / 3)}


def memory_line(route_name: str) -> MemoryLine:
    """The measured line of a route (``reference`` or a back-end's name); the steepest measured
    line for a back-end without one (a bound, not a fit)."""
    lines = {name: MemoryLine(*BACKENDS.get(name).memory_gib) for name in BACKENDS.names()
             if BACKENDS.get(name).memory_gib is not None}
    lines[REFERENCE_SOLVER] = lines[REFERENCE_BOUND]
    return lines.get(route_name, max(lines.values(), key=lambda line: line.per_dof_gib))


def route(solver: str, backend: str) -> str:
    return REFERENCE_SOLVER if solver == REFERENCE_SOLVER else backend


def predict_peak_gib(ndofs: int, solver: str, backend: str, order: int = 1,
                     dim: int = 2) -> float:
    """The predicted peak memory of a level with ``ndofs`` unknowns of order ``order`` (GiB);
    a back-end without a measured line gets the steepest one (a bound, not a fit). In 3D the
    per-DOF slope grows like N^(1/3) (a 3D factor's fill), from DIM3_FACTOR at DIM3_AT DOFs;
    a back-end with a measured 3D line (``Backend.memory_gib_3d``: no factor, no fill) uses
    that line instead."""
    name = route(solver, backend)
    measured = ({3: BACKENDS.get(name).memory_gib_3d} if name in BACKENDS.names() else {})
    if measured.get(dim):
        base, per_dof = measured[dim]
        return base + ORDER_FACTOR[order] * per_dof * ndofs
    line = memory_line(name)
    factor, at, exponent = FILL[dim]
    per_dof = ORDER_FACTOR[order] * line.per_dof_gib * factor * max(ndofs / at, 1.0) ** exponent
    return line.base_gib + per_dof * ndofs


@dataclass(frozen=True)
class MemoryRoute:
    """How a level's predicted peak memory is met: ``backend``, an iterative back-end that
    replaces the configured one (None: no change), with ``note`` for the row's reason; or
    ``refusal``, why the level must not be built (None: it fits)."""

    backend: str | None = None
    note: str = ""
    refusal: str | None = None
    limit_gib: float = float("inf")  # the memory the route was chosen within


def memory_route(level: int, ndofs: int, solver: str, backend: str, limit_gib: float,
                 order: int = 1, dim: int = 2) -> MemoryRoute:
    """The route of a level of ``ndofs`` unknowns: as configured if it fits in ``limit_gib``,
    else on an iterative back-end that fits, else refused."""
    need = predict_peak_gib(ndofs, solver, backend, order, dim)
    if need <= limit_gib:
        return MemoryRoute(limit_gib=limit_gib)
    why = (f"level {level} needs ~{need:.2f} GiB ({ndofs} DOFs, {route(solver, backend)}), "
           f"{limit_gib:.2f} available")
    instead = iterative_route(ndofs, solver, backend, limit_gib, order, dim)
    if instead is not None:
        return MemoryRoute(instead, f"memory: {why}; solved by {instead} instead", None,
                           limit_gib)
    return MemoryRoute(refusal=f"memory: {why}", limit_gib=limit_gib)


def dense_block_route(chosen: MemoryRoute, level: int, ndofs: int, dense_size: int,
                      solver: str, backend: str, order: int = 1, dim: int = 2) -> MemoryRoute:
    """``chosen`` (``memory_route``, before the assembly) once the assembled level shows the
    dense Schur block of ``dense_size`` columns its condensing back-end would form
    (DENSE_COPIES arrays of dense_size^2 doubles, which the line in N does not see): on an
    iterative back-end if the two together do not fit in the memory the route was chosen
    within. Otherwise unchanged; where no iterative back-end fits either, the back-end's own
    check (``check_dense_block``) has the last word."""
    if chosen.backend is not None or chosen.refusal is not None or dense_size == 0:
        return chosen
    dense = DENSE_COPIES * 8.0 * dense_size**2 / 2**30
    need = predict_peak_gib(ndofs, solver, backend, order, dim) + dense
    if need <= chosen.limit_gib:
        return chosen
    instead = iterative_route(ndofs, solver, backend, chosen.limit_gib, order, dim)
    if instead is None:
        return chosen
    why = (f"level {level}'s dense Schur block of {dense_size} contact DOFs needs "
           f"~{dense:.2f} GiB ({backend}), ~{need:.2f} GiB with the rest, "
           f"{chosen.limit_gib:.2f} available")
    return MemoryRoute(instead, f"memory: {why}; solved by {instead} instead", None,
                       chosen.limit_gib)


def iterative_route(ndofs: int, solver: str, backend: str, limit_gib: float, order: int = 1,
                    dim: int = 2) -> str | None:
    """The iterative back-end (``Backend.iterative``) of lowest rank that fits in
    ``limit_gib`` (``memory_route`` asks where ``backend`` does not), for the fast solver (the
    reference uses no back-end); None if none does."""
    if solver == REFERENCE_SOLVER:
        return None
    candidates = sorted((BACKENDS.get(name) for name in BACKENDS.names()),
                        key=lambda b: b.rank)
    for candidate in candidates:
        if candidate.iterative and not candidate.missing and candidate.name != backend and \
                predict_peak_gib(ndofs, solver, candidate.name, order, dim) <= limit_gib:
            return candidate.name
    return None


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


def level_memory(level: int, ndofs: int, solver: str, config,
                 dim: int = 2) -> MemoryRoute:
    """The memory route of a level (``bench.sequence.memory.memory_route``) within
    ``config.max_memory_gib``, or the memory available now."""
    backend = check_backend(config.options().get("backend"))
    limit = config.max_memory_gib if config.max_memory_gib is not None else available_gib()
    return memory_route(level, ndofs, solver, backend, limit, config.order, dim)


def memory_refusal(level: int, ndofs: int, solver: str, config,
                   dim: int = 2) -> str | None:
    """Why a level of ``ndofs`` unknowns must not be built (its predicted peak memory does not
    fit on any back-end), or None."""
    return level_memory(level, ndofs, solver, config, dim).refusal


def level_refusal(level: int, ndofs: int, config,
                  route: MemoryRoute) -> tuple[str, str] | None:
    """Why a level of ``ndofs`` unknowns is not built, as (end of the sequence, the failed
    row's reason, '' for none), or None: over the DOF budget (a failed row only for the
    starting mesh) or over the memory (``route``, from ``level_memory``)."""
    if ndofs > config.max_dofs:
        return "budget", (f"budget: the starting mesh has {ndofs} DOFs, over max_dofs="
                          f"{config.max_dofs}" if level == 0 else "")
    return None if route.refusal is None else ("memory", route.refusal)

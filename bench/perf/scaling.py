"""The scaling table: time of each phase and peak memory against problem size.

``python -m bench scaling`` runs, for each size, in a fresh process (so that the peak resident
memory belongs to that size alone): assembly of the mixed method on a uniform mesh of the paper
scene, one plain linear solve of the same stiffness matrix with the same back-end (the physical
floor), the fast contact solve (``active-set``, cold start), the residual estimator, and the
reference solve (CVXPY + Clarabel) up to ``reference_max_dofs``. Same workloads as the
pytest-benchmark module ``tests/benchmarks``.
"""

from __future__ import annotations

import itertools
import multiprocessing
import platform
import resource
import time
from pathlib import Path

import numpy as np
import pandas as pd

from bench.matrix.files import atomic_text
from bench.perf.system_scaling import measure_systems, system_table, warm_up_systems
from formulations.solvers.registry import FAST_SOLVER, REFERENCE_SOLVER

# (initial_divisions, uniform refinements) of the paper scene for ~10^4, 10^5, 10^6 DOFs
SIZES = {"1e4": (9, 3), "1e5": (14, 4), "1e6": (11, 6)}
README_START, README_END = "<!-- scaling:start -->", "<!-- scaling:end -->"


def paper_problem(size: str, order: int = 1):
    """(scene, mesh) of the paper scene with about ``size`` DOFs of order ``order`` (for
    order > 1: the uniform level of the P1 size's mesh whose DOF count is nearest to it)."""
    from formulations.elasticity import count_free_dofs
    from scenes import get_scene

    if size not in SIZES:
        raise ValueError(f"size={size!r} is not one of {', '.join(SIZES)}")
    divisions, refinements = SIZES[size]
    scene = get_scene("paper", initial_divisions=divisions)
    target = count_free_dofs(scene, scene.mesh.refined(refinements))
    levels = range(refinements + 1) if order > 1 else [refinements]
    best = min(levels, key=lambda r: abs(np.log(count_free_dofs(
        scene, scene.mesh.refined(r), order) / target)))
    return scene, scene.mesh.refined(best)


def linear_rhs(qp) -> np.ndarray:
    """Right-hand side of the plain linear solve: a unit pressure on every contact row (the
    paper scene's F is zero, and a solve with b = 0 would prove nothing)."""
    return qp.F - qp.B.T @ np.ones(qp.m)


def peak_gib() -> float:
    """This process's peak resident memory so far (GiB)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20  # KiB on Linux


def in_fresh_process(function, *args):
    """``function(*args)`` in a newly spawned process, so that its peak memory is its own."""
    with multiprocessing.get_context("spawn").Pool(1) as pool:
        return pool.apply(function, args)


def measure(size: str, backend: str | None = None, reference: bool = True,
            order: int = 1) -> dict:
    """Time every phase once at ``size``; run in a fresh process for a meaningful peak
    (``peak_gib_mixed``: after the mixed method's assembly, solves and estimator;
    ``peak_gib_without_reference``: after the semismooth systems too)."""
    from estimators import get_estimator
    from formulations import get_formulation, solve
    from formulations.solvers.backends import check_backend

    backend = check_backend(backend)
    warm_up(backend)
    scene, mesh = paper_problem(size, order)
    start = time.perf_counter()
    disc = get_formulation("mixed")(scene, mesh, order=order)
    row = {"size": size, "order": order, "ndofs": disc.ndofs, "n_constraints": disc.qp.m,
           "backend": backend,
           "t_assemble": time.perf_counter() - start}
    fast = time_linear_and_fast(disc, backend, row)
    row.update({phase_column(name): seconds for name, seconds in fast.diagnostics.phases})
    start = time.perf_counter()
    get_estimator("residual")(scene, fast)
    row["t_estimate"] = time.perf_counter() - start
    row["peak_gib_mixed"] = peak_gib()  # one formulation's whole level, as a sequence has it
    row.update(measure_systems(scene, mesh, order, backend))
    row["peak_gib_without_reference"] = peak_gib()
    row.update(t_reference_solve=np.nan, reference_iterations=0, reference_status="not run",
               energy_norm_difference=np.nan, max_lambda_difference=np.nan)
    if reference:
        from bench.measure.difference import solution_difference

        reference = solve(disc, REFERENCE_SOLVER)
        energy, pressure = solution_difference(disc, fast, reference)
        row.update(t_reference_solve=reference.solve_time,
                   reference_iterations=reference.iterations,
                   reference_status=reference.status, energy_norm_difference=energy,
                   max_lambda_difference=pressure)
    row["peak_gib"] = peak_gib()
    return row


def time_linear_and_fast(disc, backend: str, row: dict):
    """One plain linear solve of the QP's K (``t_linear_solve``) and the fast contact solve
    (``t_fast_solve`` and its iterations, status and largest residual; the Krylov iterations
    of both on an iterative back-end) into ``row``; returns the fast solution."""
    from formulations import solve
    from formulations.solvers.backends import factorise

    start = time.perf_counter()
    linear = factorise(disc.qp.K, backend, disc.qp.near_null)
    linear(linear_rhs(disc.qp))
    row["t_linear_solve"] = time.perf_counter() - start
    fast = solve(disc, FAST_SOLVER, backend=backend)
    row.update(t_fast_solve=fast.solve_time, fast_iterations=fast.iterations,
               fast_status=fast.status, fast_max_residual=max(vars(fast.residuals).values()),
               # an iterative back-end's Krylov iterations (0 for a factorisation)
               linear_krylov_iterations=sum(getattr(linear, "iterations", ())),
               fast_krylov_iterations=sum(fast.diagnostics.krylov_iterations))
    return fast


def warm_up(backend: str) -> None:
    """Load the back-end's library and run every route's one-time set-up (a plain factorisation
    and a small active-set solve) before any clock: the table compares per-level costs, which a
    sequence pays on every level."""
    from formulations.solvers.active_set import cycling_qp, solve_active_set
    from formulations.solvers.backends import factorise

    qp = cycling_qp()
    factorise(qp.K, backend)(qp.F)
    solve_active_set(qp, backend=backend)
    warm_up_systems(backend)


def phase_column(phase: str) -> str:
    """The scaling column of a phase of the fast solve ("schur block" -> t_fast_schur_block)."""
    return "t_fast_" + phase.replace(" ", "_").replace("-", "_")


def phase_table(frame: pd.DataFrame) -> str:
    """Where the fast contact solve's time goes (the condensed route), per size."""
    columns = [c for c in frame.columns if c.startswith("t_fast_") and c != "t_fast_solve"]
    if not columns:
        return ""
    table = frame[["order", "ndofs", "t_linear_solve", "t_fast_solve", *columns]].copy()
    table[["order", "ndofs"]] = table[["order", "ndofs"]].astype(int).astype(str)
    table.columns = ["order", "N (DOFs)", "linear solve [s]", "fast solve [s]",
                     *[c.removeprefix("t_fast_").replace("_", " ") + " [s]" for c in columns]]
    return table.to_markdown(index=False, floatfmt=".2f")


def run_scaling(sizes, backend=None, reference_max_dofs=200_000, on_row=None,
                orders=(1,)) -> pd.DataFrame:
    """``measure`` every size (and order) in its own spawned process; the reference only up to
    ``reference_max_dofs`` (its time grows fastest; docs/solvers.md says where it stops)."""
    from formulations.elasticity import count_free_dofs

    rows = []
    for size, order in itertools.product(sizes, orders):
        scene, mesh = paper_problem(size, order)  # cheap: the DOF count decides the reference
        ndofs = count_free_dofs(scene, mesh, order)
        row = in_fresh_process(measure, size, backend, ndofs <= reference_max_dofs, order)
        rows.append(row)
        if on_row is not None:
            on_row(row)
    frame = pd.DataFrame(rows)
    frame["fast_over_linear"] = frame["t_fast_solve"] / frame["t_linear_solve"]
    frame["reference_over_fast"] = frame["t_reference_solve"] / frame["t_fast_solve"]
    return frame


def machine_line() -> str:
    import os

    return (f"{platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}"
            f", {platform.platform()}")


def markdown_table(frame: pd.DataFrame) -> str:
    table = pd.DataFrame({
        "order": frame["order"] if "order" in frame else 1,
        "N (DOFs)": frame["ndofs"],
        "contact rows": frame["n_constraints"],
        "assembly [s]": frame["t_assemble"].map("{:.2f}".format),
        "linear solve [s]": frame["t_linear_solve"].map("{:.2f}".format),
        "fast contact solve [s]": frame["t_fast_solve"].map("{:.2f}".format),
        "fast / linear": frame["fast_over_linear"].map("{:.2f}".format),
        "iterations": frame["fast_iterations"],
        "reference solve [s]": frame["t_reference_solve"].map(
            lambda t: "not run" if t != t else f"{t:.2f}"),
        "reference / fast": frame["reference_over_fast"].map(
            lambda r: "" if r != r else f"{r:.1f}x"),
        "energy-norm difference": frame["energy_norm_difference"].map(
            lambda d: "" if d != d else f"{d:.1e}"),
        "max lambda difference": frame["max_lambda_difference"].map(
            lambda d: "" if d != d else f"{d:.1e}"),
        "estimator [s]": frame["t_estimate"].map("{:.2f}".format),
        "peak memory, mixed level [GiB]": frame["peak_gib_mixed"].map("{:.2f}".format)
        if "peak_gib_mixed" in frame else "",
        "peak memory without reference [GiB]": frame["peak_gib_without_reference"].map(
            "{:.2f}".format),
        "peak memory [GiB]": frame["peak_gib"].map("{:.2f}".format),
    })
    backend = ", ".join(sorted(set(frame["backend"])))
    return (f"Back-end: {backend}. Machine: {machine_line()}.\n\n"
            + table.to_markdown(index=False))


def write_scaling(frame: pd.DataFrame, out: str | Path, readme: str | Path | None = None):
    """Write OUT/scaling.{csv,md}; with ``readme``, replace the table between the README's
    scaling markers."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    frame.to_csv(out / "scaling.csv", index=False)
    text = markdown_table(frame)
    phases, systems = phase_table(frame), system_table(frame)
    if systems:
        text += ("\n\nFormulations that are a semismooth system, solved by active-set "
                 f"(semismooth Newton, cold start):\n\n{systems}")
    (out / "scaling.md").write_text(text + "\n" + (
        f"\nPhases of the fast contact solve:\n\n{phases}\n" if phases else ""))
    if readme is not None:
        replace_in_readme(readme, README_START, README_END, text)
    return out / "scaling.md"


def check_markers(readme: str | Path, start: str, end: str) -> str:
    """The text of ``readme``; ValueError when it is not a readable file holding both
    markers (checked before anything is measured, and again when the block is written)."""
    readme = Path(readme)
    try:
        content = readme.read_text()
    except (OSError, UnicodeDecodeError) as error:
        reason = getattr(error, "strerror", None) or type(error).__name__
        raise ValueError(f"readme={str(readme)!r} cannot be read ({reason}); give a Markdown "
                         f"file with the markers {start} ... {end}") from None
    if start not in content or end not in content:
        raise ValueError(f"readme={str(readme)!r} has no {start} ... {end} markers; add them "
                         "where the table goes")
    return content


def replace_in_readme(readme: str | Path, start: str, end: str, text: str) -> None:
    """Replace what lies between the markers ``start`` and ``end`` of ``readme`` by ``text``."""
    content = check_markers(readme, start, end)
    head, rest = content.split(start, 1)
    tail = rest.split(end, 1)[1]
    atomic_text(f"{head}{start}\n{text}\n{end}{tail}", Path(readme))

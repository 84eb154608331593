"""The 3D scaling table (docs/theory.md, section 14.5): per size, in a fresh process, the
assembly of ``vi`` on a uniform mesh of ``paper-3d``, one plain linear solve of its stiffness
matrix (the floor), the fast contact solve (``active-set``, cold start), the residual estimator
and the peak resident memory. ``vi`` is the formulation with a QP in 3D whose constraint count
(one per contact node) matches the 2D table's mixed method in kind."""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import pandas as pd

from bench.perf.scaling import (
    in_fresh_process,
    machine_line,
    peak_gib,
    replace_in_readme,
    time_linear_and_fast,
    warm_up,
)
from formulations.solvers.registry import FAST_SOLVER

# (initial_divisions, uniform refinements) of paper-3d: n = d 2^r cubes per side and
# 3 n (n + 1)^2 P1 unknowns (the top face clamped): 9 000, 1.0e5, 5.5e5
SIZES_3D = {"1e4": (7, 1), "1e5": (4, 3), "5e5": (7, 3)}
README_START_3D, README_END_3D = "<!-- scaling3d:start -->", "<!-- scaling3d:end -->"


def paper_3d_problem(size: str, order: int = 1):
    """(scene, mesh) of paper-3d with about ``size`` P1 DOFs (P2 on the mesh of the same P1
    size: about eight times the unknowns, so P2 sizes are halved in refinements)."""
    from scenes import get_scene

    if size not in SIZES_3D:
        raise ValueError(f"size={size!r} is not one of {', '.join(SIZES_3D)}")
    divisions, refinements = SIZES_3D[size]
    scene = get_scene("paper-3d", initial_divisions=divisions)
    return scene, scene.mesh.refined(refinements - (order - 1))


def measure_3d(size: str, backend: str | None = None, order: int = 1) -> dict:
    """Time every phase once at ``size`` (run in a fresh process for a meaningful peak)."""
    from estimators import get_estimator
    from formulations import get_formulation
    from formulations.solvers.backends import check_backend

    backend = check_backend(backend)
    warm_up(backend)
    scene, mesh = paper_3d_problem(size, order)
    start = time.perf_counter()
    disc = get_formulation("vi")(scene, mesh, order=order)
    row = {"size": size, "order": order, "dim": 3, "ndofs": disc.ndofs,
           "n_constraints": disc.qp.m, "backend": backend,
           "t_assemble": time.perf_counter() - start}
    fast = time_linear_and_fast(disc, backend, row)
    row["active_constraints"] = fast.active_constraints
    start = time.perf_counter()
    get_estimator("residual")(scene, fast)
    row["t_estimate"] = time.perf_counter() - start
    row["peak_gib"] = peak_gib()
    return row


def run_scaling_3d(sizes, backend=None, orders=(1,), on_row=None) -> pd.DataFrame:
    rows = []
    for size in sizes:
        for order in orders:
            row = in_fresh_process(measure_3d, size, backend, order)
            rows.append(row)
            if on_row is not None:
                on_row(row)
    frame = pd.DataFrame(rows)
    frame["fast_over_linear"] = frame["t_fast_solve"] / frame["t_linear_solve"]
    return frame


def markdown_table_3d(frame: pd.DataFrame) -> str:
    table = pd.DataFrame({
        "order": frame["order"], "N (DOFs)": frame["ndofs"],
        "contact rows": frame["n_constraints"], "active": frame["active_constraints"],
        "assembly [s]": frame["t_assemble"].map("{:.2f}".format),
        "linear solve [s]": frame["t_linear_solve"].map("{:.2f}".format),
        "fast contact solve [s]": frame["t_fast_solve"].map("{:.2f}".format),
        "fast / linear": frame["fast_over_linear"].map("{:.2f}".format),
        "iterations": frame["fast_iterations"],
        "Krylov iterations (linear / contact)": krylov_column(frame),
        "estimator [s]": frame["t_estimate"].map("{:.2f}".format),
        "peak memory [GiB]": frame["peak_gib"].map("{:.2f}".format),
        "memory model [GiB]": pd.Series(expected_peak_gib(frame)).map("{:.2f}".format),
    })
    backend = ", ".join(sorted(set(frame["backend"])))
    return (f"paper-3d, vi, uniform tetrahedral meshes. Back-end: {backend}. Machine: "
            f"{machine_line()}.\n\n" + table.to_markdown(index=False))


def krylov_column(frame: pd.DataFrame) -> pd.Series:
    """'linear / contact' Krylov iterations on an iterative back-end; '' for a factorisation
    (and for tables measured before the columns existed)."""
    if "fast_krylov_iterations" not in frame:
        return pd.Series([""] * len(frame), index=frame.index)
    pairs = zip(frame["linear_krylov_iterations"], frame["fast_krylov_iterations"],
                strict=True)
    return pd.Series([f"{int(a)} / {int(b)}" if b else "" for a, b in pairs],
                     index=frame.index)


def write_scaling_3d(frame: pd.DataFrame, out: str | Path, readme: str | Path | None = None):
    """Write OUT/scaling-3d.{csv,md}; with ``readme``, replace its 3D scaling block."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    frame.to_csv(out / "scaling-3d.csv", index=False)
    text = markdown_table_3d(frame)
    (out / "scaling-3d.md").write_text(text + "\n")
    if readme is not None:
        replace_in_readme(readme, README_START_3D, README_END_3D, text)
    return out / "scaling-3d.md"


def expected_peak_gib(frame: pd.DataFrame) -> np.ndarray:
    """The memory model's prediction for each row (``bench.sequence.memory``), to set beside
    the measured peak."""
    from bench.sequence.memory import predict_peak_gib

    return np.array([predict_peak_gib(int(n), FAST_SOLVER, b, int(o), 3)
                     for n, b, o in zip(frame["ndofs"], frame["backend"], frame["order"],
                                        strict=True)])

"""The sequence benchmark (``python -m bench scaling --sequence``): whole refinement sequences of
the paper scene (mixed method, active set, residual estimator, errors against the cached
reference), every level and every phase timed, against one plain linear solve of the finest
level's stiffness matrix with the same back-end.

Each sequence runs in a fresh process (its peak memory is its own). The phases of a level are
the row's own timings (assembly, contact solve, estimator, refinement including marking,
diagnostics, error against the reference) plus the time the result store took to write the
row; ``t_sequence`` is the wall time of the whole sequence, everything included.
"""

from __future__ import annotations

import itertools
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd

from formulations.cells import DEFAULT_CELL
from formulations.solvers.registry import FAST_SOLVER

# (strategy, DOF budget): the sequences the benchmark runs by default
SEQUENCES = (("adaptive", 1_000_000), ("uniform", 2_200_000))  # uniform: to 2.1e6
LEVEL_PHASES = ("t_assemble", "t_solve", "t_estimate", "t_refine", "t_diagnostics", "t_error")
REFERENCE_DOFS = 200_000  # compare's default reference budget
README_START, README_END = "<!-- sequence:start -->", "<!-- sequence:end -->"


def measure_sequence(strategy: str, max_dofs: int, backend: str | None = None,
                     reference_dofs: int = REFERENCE_DOFS, cell: str = DEFAULT_CELL,
                     stopping: str = "fixed") -> dict:
    """Run one sequence and time it (``stopping``: the solvers' stopping rule, docs/theory.md
    18); run in a fresh process for a meaningful peak."""
    from bench.matrix.store import ResultStore
    from bench.perf.scaling import peak_gib
    from bench.sequence.loop import LoopConfig, run_sequence
    from bench.truth import truth_for
    from formulations.solvers.backends import check_backend, factorise, iterative
    from scenes import get_scene

    backend = check_backend(backend)
    scene = get_scene("paper")
    truth = truth_for(scene, reference_dofs, max_dofs)
    # the inf-sup constant costs m Krylov solves per level on an iterative back-end (no
    # condensed system to reuse): a diagnostic the sequence's cost should not be measured with
    config = LoopConfig(strategy=strategy, max_dofs=max_dofs, max_levels=60, cell=cell,
                        backend=backend, stopping=stopping, diagnostics=not iterative(backend))
    rows, t_store, last = [], 0.0, None
    with tempfile.TemporaryDirectory() as folder:
        store = ResultStore(folder)
        start = time.perf_counter()
        for result in run_sequence(scene, "mixed", FAST_SOLVER, "residual", config,
                                   truth=truth):
            clock = time.perf_counter()
            store.append(result.row)
            t_store += time.perf_counter() - clock
            rows.append(result.row)
            last = result
        t_sequence = time.perf_counter() - start
    frame = pd.DataFrame([vars(row) for row in rows])
    K = last.solution.elasticity.K_free
    clock = time.perf_counter()
    factorise(K, backend, last.solution.elasticity.rigid_modes)(np.ones(K.shape[0]))
    t_linear = time.perf_counter() - clock
    out = {"strategy": strategy, "cell": cell, "max_dofs": max_dofs, "backend": backend,
           "stopping": stopping, "krylov_iterations": int(frame["krylov_iterations"].sum()),
           "newton_steps": int(frame["newton_steps"].sum()),
           "energy_error_finest": float(frame["energy_error"].iloc[-1]),
           "levels": len(rows), "final_ndofs": int(frame["ndofs"].iloc[-1]),
           "status": ",".join(sorted(set(frame["status"]))), "t_sequence": t_sequence,
           "t_linear_finest": t_linear}
    for phase in LEVEL_PHASES:
        out[phase] = float(frame[phase].fillna(0.0).sum())
        out[phase + "_finest"] = float(np.nan_to_num(frame[phase].iloc[-1]))
    out.update(t_store=t_store, sequence_over_linear=t_sequence / t_linear,
               peak_gib=peak_gib())
    return out


def run_sequences(sequences=SEQUENCES, backend=None, on_row=None,
                  cells=(DEFAULT_CELL,), stopping=("fixed",)) -> pd.DataFrame:
    """``measure_sequence`` for every (strategy, budget), cell shape and stopping rule, each
    in its own spawned process."""
    from bench.perf.scaling import in_fresh_process

    rows = []
    for (strategy, max_dofs), cell, rule in itertools.product(sequences, cells, stopping):
        row = in_fresh_process(measure_sequence, strategy, max_dofs, backend, REFERENCE_DOFS,
                               cell, rule)
        rows.append(row)
        if on_row is not None:
            on_row(row)
    return pd.DataFrame(rows)


def sequence_table(frame: pd.DataFrame) -> str:
    """Markdown: each sequence's wall time and its phases, in units of the finest linear
    solve."""
    table = pd.DataFrame({
        "sequence": frame["strategy"] + " to " + frame["max_dofs"].map(
            lambda n: f"{n:.2g}".replace("e+0", "e").replace("e+", "e"))
        + frame.get("cell", pd.Series("tri", index=frame.index)).map(
            lambda c: "" if c == DEFAULT_CELL else f", {c}")
        + frame.get("stopping", pd.Series("fixed", index=frame.index)).map(
            lambda r: "" if r == "fixed" else f", {r} stopping"),
        "levels": frame["levels"], "finest N": frame["final_ndofs"],
        "whole sequence [s]": frame["t_sequence"].map("{:.1f}".format),
        "linear solve at finest [s]": frame["t_linear_finest"].map("{:.2f}".format),
        "sequence / linear": frame["sequence_over_linear"].map("{:.1f}".format),
        "peak [GiB]": frame["peak_gib"].map("{:.2f}".format),
        "Krylov iterations": frame.get("krylov_iterations", pd.Series(0, index=frame.index)),
        "error at finest": frame.get("energy_error_finest", pd.Series(np.nan, index=frame.index))
        .map("{:.3g}".format),
    })
    for phase in (*LEVEL_PHASES, "t_store"):
        name = phase.removeprefix("t_")
        table[f"{name} [s]"] = frame[phase].map("{:.1f}".format)
    finest = pd.DataFrame({"sequence": table["sequence"]})
    for phase in LEVEL_PHASES:
        finest[phase.removeprefix("t_") + " / linear"] = (
            frame[phase + "_finest"] / frame["t_linear_finest"]).map("{:.2f}".format)
    return (table.to_markdown(index=False) + "\n\nThe finest level's phases, in units of its "
            "linear solve:\n\n" + finest.to_markdown(index=False))


def write_sequences(frame: pd.DataFrame, out: str | Path, readme: str | Path | None = None):
    """Write OUT/scaling-sequence.{csv,md}; with ``readme``, replace the table between the
    README's sequence markers."""
    from bench.perf.scaling import machine_line, replace_in_readme

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    frame.to_csv(out / "scaling-sequence.csv", index=False)
    backend = ", ".join(sorted(set(frame["backend"])))
    text = (f"Back-end: {backend}. Machine: {machine_line()}.\n\n" + sequence_table(frame))
    (out / "scaling-sequence.md").write_text(text + "\n")
    if readme is not None:
        replace_in_readme(readme, README_START, README_END, text)
    return out / "scaling-sequence.md"

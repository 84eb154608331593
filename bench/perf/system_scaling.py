"""The scaling table's columns for the formulations that are a semismooth system (nitsche):
their ``active-set`` solve (semismooth Newton, cold start) on the scaling problem's mesh, set
against the same plain linear solve as the QP route. Which formulations: every registered one
whose discretisation offers a system, so a new one joins without an edit here."""

from __future__ import annotations

import numpy as np
import pandas as pd

from formulations.solvers.registry import FAST_SOLVER


def system_formulations(scene) -> list[str]:
    """The registered formulations whose discretisation of ``scene``'s coarsest mesh is a
    semismooth system."""
    from formulations import formulation_names, get_formulation

    return [name for name in formulation_names()
            if get_formulation(name)(scene, scene.mesh).system is not None]


def measure_systems(scene, mesh, order: int, backend: str) -> dict:
    """t_<name>_solve, <name>_iterations, <name>_status and <name>_max_residual per system
    formulation (cold start, the back-end of the QP route), and ``system_formulations``, the
    names measured."""
    from formulations import get_formulation, solve

    names = system_formulations(scene)
    row = {"system_formulations": ",".join(names)}
    for name in names:
        disc = get_formulation(name)(scene, mesh, order=order)
        sol = solve(disc, FAST_SOLVER, backend=backend)
        row.update({f"t_{name}_solve": sol.solve_time, f"{name}_iterations": sol.iterations,
                    f"{name}_status": sol.status,
                    f"{name}_max_residual": max(vars(sol.residuals).values()),
                    f"{name}_phases": ", ".join(f"{phase} {seconds:.2f}"
                                                for phase, seconds in sol.diagnostics.phases)})
    return row


def system_table(frame: pd.DataFrame) -> str:
    """One Markdown table of the system formulations' solves against the linear solve."""
    if "system_formulations" not in frame:
        return ""
    names = sorted({n for text in frame["system_formulations"].dropna() for n in
                    str(text).split(",") if n})
    if not names:
        return ""
    table = pd.DataFrame({"order": frame["order"].astype(int), "N (DOFs)": frame["ndofs"],
                          "linear solve [s]": frame["t_linear_solve"].map("{:.2f}".format)})
    for name in names:
        time = frame[f"t_{name}_solve"]
        table[f"{name} solve [s]"] = time.map("{:.2f}".format)
        table[f"{name} / linear"] = (time / frame["t_linear_solve"]).map("{:.2f}".format)
        table[f"{name} Newton iterations"] = frame[f"{name}_iterations"]
        table[f"{name} residual"] = frame[f"{name}_max_residual"].map(
            lambda r: "" if not np.isfinite(r) else f"{r:.1e}")
        table[f"{name} phases [s]"] = frame[f"{name}_phases"]
    return table.to_markdown(index=False)


def warm_up_systems(backend: str) -> None:
    """One small solve of every system formulation before any clock (library set-up on first
    use, as ``scaling.warm_up`` does for the QP route)."""
    from formulations import get_formulation, solve
    from scenes import get_scene

    scene = get_scene("paper")
    for name in system_formulations(scene):
        solve(get_formulation(name)(scene, scene.mesh.refined(2)), FAST_SOLVER, backend=backend)

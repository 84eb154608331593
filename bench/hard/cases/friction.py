"""Friction from none to almost full stick: the Coulomb coefficient mu = 0, 0.3 and 10 on the
paper scene (at 10 the plain fixed point cycles and is relaxed), and a stick-slip boundary
inside an element (docs/theory.md, 17.3 and 17.6)."""

from __future__ import annotations

import pandas as pd
from matplotlib.figure import Figure

from bench.hard.registry import case_figure, hard_case
from bench.hard.verdicts import solve_both
from formulations.registry import FORMULATIONS
from formulations.solvers.registry import FAST_SOLVER
from scenes import get_scene

# mu = 30, where the fixed point contracts too slowly and fails (vi, penalty), is a unit test
# (tests/formulations/friction/test_nodal_friction.py): its reference solves alone take ~25 s
COEFFICIENTS = (0.0, 0.3, 10.0)
LEVEL = 3  # 2112 P1 DOFs: at level 2 every mu >= 1 sticks everywhere, no cycle to see


def _solve_every_formulation(scene, variant: str) -> list[dict]:
    """Every formulation that models the scene's friction, with every solver, at LEVEL."""
    records = []
    for formulation in FORMULATIONS.names():
        if FORMULATIONS.why_not(formulation, scene=scene) is not None:
            continue
        rows, solutions = solve_both("friction", scene, formulation, scene.mesh.refined(LEVEL),
                                     variant=variant, level=LEVEL)
        for row, solution in zip(rows, solutions, strict=True):
            row["finding"] = _finding(row, solution)
        records += rows
    return records


def _finding(row: dict, solution) -> str:
    state = solution.friction
    if state is None:
        return "frictionless"
    counts = {name: int((state.state == name).sum()) for name in ("stick", "slip")}
    return f"{counts['stick']} points stick, {counts['slip']} slip; {row['iterations']} " \
           "Tresca iterations in all"


@hard_case("friction", "Coulomb friction mu = 0, 0.3, 10 on the paper scene (frictionless to "
                       "almost full stick; the fixed point cycles at 10 and is relaxed) and a "
                       "stick-slip boundary inside an element",
            meta={"seconds": 20})  # measured on 2 cores: the default test run leaves it out
def friction_sweep() -> list[dict]:
    records = []
    for mu in COEFFICIENTS:  # mu = 0: the frictionless scene, every formulation
        scene = get_scene("paper", **({"friction": "coulomb", "mu": mu} if mu else {}))
        records += _solve_every_formulation(scene, f"mu={mu:g}")
    # b = 0.2 between the nodes 0.1875 and 0.25 of level 3: the stick zone ends inside a facet
    return records + _solve_every_formulation(get_scene("stick-slip"),
                                              "stick end inside an element")


@case_figure("friction", "Coulomb friction on the paper scene against mu: the Tresca "
                         "iterations of the fixed point (fast solver) and the nodes that stick.")
def friction_figure(rows: pd.DataFrame):
    fig = Figure(figsize=(6, 4))
    ax = fig.subplots()
    fast = rows[(rows["solver"] == FAST_SOLVER) & rows["variant"].str.startswith("mu=")
                & (rows["formulation"] == "vi")]
    mu = fast["variant"].str.split("=").str[1].astype(float)
    ax.semilogx(mu.clip(lower=0.01), fast["iterations"], marker="o",
                label="Tresca iterations (mu = 0 drawn at 0.01)")
    failed = fast["status"] == "failed"
    ax.semilogx(mu[failed].clip(lower=0.01), fast["iterations"][failed], "rx", markersize=10,
                label="fixed point did not converge")
    ax.set(xlabel="mu", ylabel="iterations", title="Coulomb fixed point (vi P1, paper)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    return fig



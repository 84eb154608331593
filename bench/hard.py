"""The hard cases (issue 7): where a formulation or a solver may break, with a verdict for each
(hard case x formulation x solver x variant) and the measured numbers behind it.

Every discrete problem is solved by both solvers. The **loss** of a row is how far it is from
the exact discrete solution: the larger of its own KKT residuals (``formulations.kkt``) and its
relative energy-norm difference to the better-certified of the two answers (the one with the
smaller residuals; for a convex QP, residuals at round-off certify the minimiser); its
**pressure loss** is the max pressure difference to that answer, relative to max lambda_h. The
pressure counts because a penalty pressure (u_hn - g_h)_+ / eps magnifies an error in u by
1/eps: an answer can be right in energy and wrong in pressure. Verdicts:

* ``accurate``: converged, loss <= ``LOSS_TOLERANCE`` and pressure loss <=
  ``PRESSURE_TOLERANCE``;
* ``inaccurate``: converged (status ok or inaccurate) but above either bar -- the loss columns
  give the measured loss;
* ``failed``: no solution; the reason says why;
* ``refused``: an invalid problem, rejected with a clear error before any solve.

``finding`` states what the case is about, measured (inf-sup decay, penetration, scaling...).
The expected verdicts live in ``bench/expected.toml`` ([[hard]]), checked by
``python -m bench verify`` and tests/bench/test_hard.py.
"""

from __future__ import annotations

import fnmatch
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd

from bench.errors import contact_zone, solution_difference
from formulations import STATUS_FAILED, get_formulation, solve
from formulations.diagnostics import inf_sup_constant, pressure_oscillation
from scenes import Scene, SceneError, get_scene

LOSS_TOLERANCE = 1e-6  # the same bar as a residual for status "ok" (formulations.kkt)
# the pressure is a pointwise, derived quantity: the reference (tolerances 1e-10) gets the mixed
# multipliers to ~1e-8, but the penalty pressure only to 1e-5..4e-4 at the default eps_0 = 1e-3
# (measured), which is still a usable answer; 0.1 % (as the penalty's own self-check,
# formulations.penalty.PRESSURE_CONSISTENCY) separates that from a wrong pressure
PRESSURE_TOLERANCE = 1e-3
SOLVERS = ("active-set", "reference")
FORMULATIONS = ("mixed", "penalty", "vi")
HARD_SCENE_LEVEL = 3  # refinements of each hard scene's initial mesh (544..4752 DOFs)
# a discretisation is "settled" when the contact force changes by at most this much from one
# uniform level to the next (the well-resolved cases here change by a few per cent)
SETTLED = 0.1
CASES: dict[str, tuple[Callable[[], list[dict]], str]] = {}


def hard_case(name: str, description: str):
    def register(run):
        CASES[name] = (run, description)
        return run
    return register


def penetration(scene: Scene, solution) -> float:
    """max over the contact nodes of (u_h . n - g)^+ (a length)."""
    trace, ends = solution.trace, np.array([0.0, 1.0])
    u_n = trace.normal_displacement(solution.elasticity.nodal(solution.u), ends)
    gap = np.asarray(scene.gap(trace.points(ends)))
    return float(np.maximum(u_n - gap, 0.0).max(initial=0.0))


def _record(case, scene, disc, sol, variant, level) -> dict:
    residual = max(vars(sol.residuals).values())
    return dict(case=case, scene=scene.name, formulation=disc.formulation, solver=sol.solver,
                variant=variant, level=level, ndofs=disc.ndofs, status=sol.status,
                reason=sol.reason, backend=sol.backend,
                safeguard=sol.diagnostics.get("safeguard", ""),
                iterations=sol.iterations, max_residual=residual,
                condition_estimate=sol.diagnostics.get("condition_estimate", np.nan),
                inf_sup=np.nan, pressure_oscillation=pressure_oscillation(sol),
                contact_force=sol.contact_force() if sol.status != STATUS_FAILED else np.nan,
                active_constraints=sol.active_constraints, n_constraints=disc.qp.m,
                penetration=penetration(scene, sol) if sol.status != STATUS_FAILED else np.nan,
                finding="")


def verdict(status: str, loss: float, pressure_loss: float = 0.0) -> str:
    if status == STATUS_FAILED or not np.isfinite(loss):
        return "failed"
    accurate = loss <= LOSS_TOLERANCE and pressure_loss <= PRESSURE_TOLERANCE
    return "accurate" if status == "ok" and accurate else "inaccurate"


def solve_both(case: str, scene: Scene, formulation: str, mesh, variant: str = "",
               level: int = 0, inf_sup: bool = False, **options) -> tuple[list[dict], list]:
    """Both solvers on one discrete problem: records with loss and verdict, and the solutions."""
    disc = get_formulation(formulation)(scene, mesh, **options)
    solutions = [solve(disc, solver) for solver in SOLVERS]
    records = [_record(case, scene, disc, sol, variant, level) for sol in solutions]
    best = int(np.argmin([r["max_residual"] if np.isfinite(r["max_residual"]) else np.inf
                          for r in records]))
    beta = inf_sup_constant(disc) if inf_sup else np.nan
    for record, sol in zip(records, solutions, strict=True):
        differences = (0.0, 0.0)
        if sol is not solutions[best] and sol.status != STATUS_FAILED:
            differences = solution_difference(disc, sol, solutions[best])
        # the penalty's own pressure self-check is a measured pressure loss too
        mismatch = sol.extra.get("pressure_mismatch", 0.0)
        record.update(loss=max(record["max_residual"], differences[0]),
                      pressure_loss=max(differences[1], mismatch), inf_sup=beta)
        record["verdict"] = verdict(record["status"], record["loss"], record["pressure_loss"])
    return records, solutions


# --- the hard scenes of the catalogue: every formulation, both solvers ------------------------
HARD_SCENES = {
    "no-contact": "nothing touches", "full-contact": "all of Gamma_C pressed",
    "incompressible": "nu = 0.4999, plane strain (P1 locking)", "wedge": "kinked obstacle",
    "thin": "50:1 strip", "grazing": "u_n = g with p = 0 (no strict complementarity)",
    "traction": "load-driven contact, zone ends at a corner",
    "corner": "contact zone ends at a domain corner", "graded": "strongly graded mesh"}


def _scene_finding(name: str, row: dict, zone: tuple[float, float]) -> str:
    if name == "no-contact":
        return f"contact force {row['contact_force']:.3g} (0 expected)"
    if name == "full-contact":
        return f"{row['active_constraints']} of {row['n_constraints']} rows active"
    text = f"contact zone [{zone[0]:.3g}, {zone[1]:.3g}], force {row['contact_force']:.4g}"
    if name == "grazing":  # the weight is rho |Omega| = 4000
        text += f" = {row['contact_force'] / 4000.0:.1e} of the weight (0 in the limit)"
    return text


def _scene_case(name: str) -> Callable[[], list[dict]]:
    def run() -> list[dict]:
        scene = get_scene(name)
        mesh = scene.mesh.refined(HARD_SCENE_LEVEL)
        records = []
        for formulation in FORMULATIONS:
            rows, sols = solve_both(name, scene, formulation, mesh, level=HARD_SCENE_LEVEL)
            # is the discretisation settled? the contact force one uniform level coarser
            coarse = solve(get_formulation(formulation)(scene, scene.mesh.refined(
                HARD_SCENE_LEVEL - 1)), "active-set").contact_force()
            fine = rows[0]["contact_force"]
            change = abs(fine - coarse) / max(abs(fine), abs(coarse)) if fine or coarse else 0.0
            for row, sol in zip(rows, sols, strict=True):
                zone = contact_zone(sol) if sol.status != STATUS_FAILED else (np.nan, np.nan)
                row["finding"] = _scene_finding(name, row, zone) + \
                    f"; force changed by {change:.1%} from the level before"
                row["force_change"] = change
                row["discretisation"] = "settled" if change <= SETTLED else "unsettled"
            records += rows
        return records
    return run


for _name, _text in HARD_SCENES.items():
    hard_case(_name, f"scene {_name!r}: {_text}")(_scene_case(_name))


@hard_case("mixed-h/H", "mixed method with h/H = 1, 1/2, 1/4 on the paper scene: discrete "
                        "inf-sup constant and multiplier oscillation under refinement")
def mixed_ratio() -> list[dict]:
    scene, records = get_scene("paper"), []
    for ratio in (1.0, 0.5, 0.25):
        for level in (2, 3, 4):
            rows, _ = solve_both("mixed-h/H", scene, "mixed", scene.mesh.refined(level),
                                 variant=f"h/H={ratio:g}", level=level, inf_sup=True,
                                 h_over_H=ratio)
            records += rows
    frame = pd.DataFrame(records)
    for ratio in (1.0, 0.5, 0.25):
        part = frame[(frame["variant"] == f"h/H={ratio:g}") & (frame["solver"] == "active-set")]
        # h ~ ndofs^(-1/2): the slope of log beta against log h
        slope = -2 * np.polyfit(np.log(part["ndofs"]), np.log(part["inf_sup"]), 1)[0]
        text = (f"beta_h {part['inf_sup'].iloc[0]:.3g} -> {part['inf_sup'].iloc[-1]:.3g} "
                f"(~ h^{slope:.2f}); oscillation {part['pressure_oscillation'].iloc[-1]:.2f}")
        for record in records:
            if record["variant"] == f"h/H={ratio:g}":
                record["finding"] = text
    return records


EPSILONS_0 = (1e-1, 1e-2, 1e-4, 1e-6, 1e-8, 1e-10, 1e-12)


@hard_case("penalty-eps", "penalty with eps_0 = 1e-1 .. 1e-12 on the paper scene: penetration, "
                          "conditioning, and the reference solver's accuracy")
def penalty_sweep() -> list[dict]:
    scene, records = get_scene("paper"), []
    mesh = scene.mesh.refined(3)
    for eps in EPSILONS_0:
        rows, _ = solve_both("penalty-eps", scene, "penalty", mesh, variant=f"eps_0={eps:g}",
                             level=3, epsilon_0=eps)
        for row in rows:
            row["finding"] = f"penetration {row['penetration']:.2e}" + (
                f", condition {row['condition_estimate']:.2e}"
                if np.isfinite(row["condition_estimate"]) else "")
        records += rows
    return records


@hard_case("scale", "the paper scene with E = 1 and E = 70000: u must agree and the pressure "
                    "scale with E")
def young_scale() -> list[dict]:
    records = []
    for formulation in FORMULATIONS:
        pair = []
        for young in (1.0, 70000.0):
            scene = get_scene("paper", young_modulus=young)
            rows, sols = solve_both("scale", scene, formulation, scene.mesh.refined(3),
                                    variant=f"E={young:g}", level=3)
            pair.append((rows, sols))
        for (soft_rows, soft), (stiff_rows, stiff) in [pair]:
            for k in range(len(SOLVERS)):
                du = np.abs(soft[k].u - stiff[k].u).max() / np.abs(stiff[k].u).max()
                df = abs(70000.0 * soft[k].contact_force() / stiff[k].contact_force() - 1)
                text = f"u differs by {du:.1e}, 70000 x force by {df:.1e} (relative)"
                soft_rows[k]["finding"] = stiff_rows[k]["finding"] = text
                soft_rows[k]["scale_difference"] = stiff_rows[k]["scale_difference"] = \
                    max(du, df)
            records += soft_rows + stiff_rows
    return records


INVALID = {  # each must raise SceneError naming the parameter, the value and what is allowed
    "no clamped part": lambda: replace(get_scene("paper"),
                                       is_dirichlet=lambda x: np.zeros(x.shape[1], bool)),
    "nu = 0.5": lambda: get_scene("paper", poisson_ratio=0.5),
    "gap with NaN": lambda: replace(get_scene("paper"),
                                    gap=lambda x: np.where(x[0] > 0.5, np.nan, 0.0)),
    "E = 0": lambda: get_scene("paper", young_modulus=0.0),
}


@hard_case("invalid", "invalid problems (no clamped part, nu >= 0.5, NaN in the gap, E = 0): "
                      "refused before any solve")
def invalid() -> list[dict]:
    records = []
    for variant, build in INVALID.items():
        try:
            build()
            status, reason, result = "ok", "accepted (should have been refused)", "inaccurate"
        except SceneError as error:
            status, reason, result = "refused", str(error), "refused"
        records.append(dict(case="invalid", scene="paper", formulation="-", solver="-",
                            variant=variant, status=status, reason=reason, verdict=result,
                            finding=reason))
    return records


def run_hard(cases: list[str] | None = None, on_case=None) -> pd.DataFrame:
    """Run the named cases (default: all) and return their records as one table."""
    frames = []
    for name in cases or list(CASES):
        run, _ = CASES[name]
        frames.append(pd.DataFrame(run()))
        if on_case is not None:
            on_case(name, frames[-1])
    return pd.concat(frames, ignore_index=True)


def check_expected(table: pd.DataFrame, expected: list[dict]) -> list[dict]:
    """Each row's verdict against the first matching [[hard]] entry (default: accurate); an
    entry's verdict may list alternatives, "accurate|inaccurate", for a borderline case."""
    out = []
    for _, row in table.iterrows():
        want, source = "accurate", "default: every solve accurate"
        for entry in expected:
            if all(fnmatch.fnmatch("" if pd.isna(row[k]) else str(row[k]),
                                   str(entry.get(k, "*")))
                   for k in ("case", "formulation", "solver", "variant")):
                want, source = entry["verdict"], entry["source"]
                break
        out.append({"case": row["case"], "formulation": row["formulation"],
                    "solver": row["solver"], "variant": row["variant"],
                    "verdict": row["verdict"], "expected": want,
                    "passed": row["verdict"] in want.split("|"), "source": source})
    return out


SUMMARY = ["case", "formulation", "solver", "variant", "ndofs", "status", "safeguard",
           "iterations", "loss", "pressure_loss", "condition_estimate", "inf_sup",
           "pressure_oscillation", "discretisation", "verdict", "finding"]


def hard_display(table: pd.DataFrame) -> pd.DataFrame:
    """The verdict table as strings (the report's and the CLI's), numbers to 3 digits."""
    shown = table.reindex(columns=SUMMARY).copy()
    for column in ("loss", "pressure_loss", "condition_estimate", "inf_sup",
                   "pressure_oscillation"):
        shown[column] = shown[column].map(lambda v: "" if pd.isna(v) else f"{v:.3g}")
    for column in ("ndofs", "iterations"):
        shown[column] = shown[column].map(lambda v: "" if pd.isna(v) else f"{int(v)}")
    return shown.astype(object).where(shown.notna(), "").astype(str)


def hard_markdown(table: pd.DataFrame) -> str:
    return hard_display(table).to_markdown(index=False)


def write_hard(table: pd.DataFrame, out) -> Path:
    """``out/hard.csv`` (every column) and ``out/hard.md`` (the verdict table)."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    table.to_csv(out / "hard.csv", index=False)
    (out / "hard.md").write_text(hard_markdown(table) + "\n")
    return out / "hard.csv"

"""The hard cases (issue 7): a catalogue of problems where a formulation or a solver may break,
each run with every formulation and both solvers; ``bench.hard_verdicts`` turns every row into
a verdict (accurate, inaccurate with the measured loss, failed, refused) with the numbers
behind it. ``python -m bench hard`` runs them; the report has a section on them.

Adding a case: a function returning a list of records (``solve_both`` makes them), decorated
with ``@hard_case(name, description)``, and its expected verdicts in ``bench/expected.toml``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import numpy as np
import pandas as pd

from bench.errors import contact_zone
from bench.hard_verdicts import SOLVERS, solve_both, verdict
from formulations import STATUS_FAILED, get_formulation, solve
from formulations.kkt import judge, qp_residuals
from formulations.solvers import get_solver
from formulations.solvers.active_set import cycling_qp
from formulations.solvers.backends import available_backends
from formulations.solvers.lcp import CYCLING_EXAMPLE
from scenes import SceneError, get_scene

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


# --- the hard scenes of the catalogue: every formulation, both solvers ------------------------
HARD_SCENES = {
    "no-contact": "nothing touches", "full-contact": "all of Gamma_C pressed",
    "incompressible": "nu = 0.4999, plane strain (P1 locking)", "wedge": "kinked obstacle",
    "thin": "50:1 strip", "grazing": "u_n = g with p = 0 (no strict complementarity)",
    "traction": "load-driven contact, zone ends at a corner",
    "corner": "contact zone ends at a domain corner", "graded": "strongly graded mesh"}


def _scene_finding(scene, row: dict, zone: tuple[float, float]) -> str:
    name = scene.name
    if name == "no-contact":
        return f"contact force {row['contact_force']:.3g} (0 expected)"
    if name == "full-contact":
        return f"{row['active_constraints']} of {row['n_constraints']} rows active"
    text = f"contact zone [{zone[0]:.3g}, {zone[1]:.3g}], force {row['contact_force']:.4g}"
    if name == "grazing":  # the weight is rho |Omega|, |Omega| = 4
        weight = 4.0 * scene.parameters["density"]
        text += f" = {row['contact_force'] / weight:.1e} of the weight (0 in the limit)"
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
                row["finding"] = _scene_finding(scene, row, zone) + \
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
        (soft_rows, soft), (stiff_rows, stiff) = (
            solve_both("scale", scene, formulation, scene.mesh.refined(3),
                       variant=f"E={scene.material.young_modulus:g}", level=3)
            for scene in (get_scene("paper", young_modulus=young) for young in (1.0, 70000.0)))
        for k in range(len(SOLVERS)):
            du = np.abs(soft[k].u - stiff[k].u).max() / np.abs(stiff[k].u).max()
            df = abs(70000.0 * soft[k].contact_force() / stiff[k].contact_force() - 1)
            for row in (soft_rows[k], stiff_rows[k]):
                row["finding"] = f"u differs by {du:.1e}, 70000 x force by {df:.1e} (relative)"
                row["scale_difference"] = max(du, df)
        records += soft_rows + stiff_rows
    return records


@hard_case("cycling", "a contact QP on which the plain active-set iteration cycles "
                      "(formulations.solvers.lcp.CYCLING_EXAMPLE): the safeguard answers")
def cycling() -> list[dict]:
    qp, (_, _, start) = cycling_qp(), CYCLING_EXAMPLE
    runs = [("active-set", backend, {"warm_start": start.astype(float), "backend": backend})
            for backend in available_backends()] + [("reference", "clarabel", {})]
    records = []
    for solver, variant, options in runs:
        answer = get_solver(solver)(qp, **options)
        residuals = qp_residuals(qp, answer.u, answer.multipliers) \
            if answer.u is not None else None
        status, reason = judge(answer, residuals)
        loss = max(vars(residuals).values()) if residuals is not None else np.nan
        diag = answer.diagnostics
        records.append(dict(
            case="cycling", scene="-", formulation="lcp", solver=solver, variant=variant,
            ndofs=qp.n, status=status, reason=answer.reason or reason, backend=answer.backend,
            safeguard=diag.get("safeguard", ""), iterations=answer.iterations,
            max_residual=loss, loss=loss, pressure_loss=0.0,
            condition_estimate=diag.get("condition_estimate", np.nan),
            verdict=verdict(status, loss),
            finding=(f"plain iteration cycled: {diag.get('cycled', False)}; changes per "
                     f"iteration {','.join(map(str, diag.get('active_set_changes', ())))}"
                     if solver == "active-set" else "interior point: no active sets")))
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
            status, reason, result = "ok", "accepted (should have been refused)", "failed"
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

"""Every scene tagged ``hard`` as a hard case: every formulation that applies to it, every
solver, at HARD_SCENE_LEVEL uniform refinements, on each cell shape asked for (the variant
names a cell other than triangles), with a finding stated in the scene's own numbers and
whether the discretisation has settled."""

from __future__ import annotations

import numpy as np

from bench.hard.verdicts import REFUSED, solve_both
from bench.measure.contact import contact_zone
from formulations import STATUS_FAILED, get_formulation, solve
from formulations.cells import DEFAULT_CELL, family_for
from formulations.registry import FORMULATIONS
from formulations.solvers.registry import FAST_SOLVER
from scenes import get_scene

HARD_SCENE_LEVEL = 3  # refinements of each hard scene's initial mesh (544..4752 DOFs)
HARD_SCENE_LEVEL_3D = 1  # of a 3D one: a uniform refinement multiplies the elements by 8
HARD_SCENE_LEVELS = {2: HARD_SCENE_LEVEL, 3: HARD_SCENE_LEVEL_3D}
# a discretisation is "settled" when the contact force changes by at most this much from one
# uniform level to the next (the well-resolved cases here change by a few per cent)
SETTLED = 0.1


def hard_level(scene) -> int:
    """Uniform refinements of a hard scene's initial mesh (2D: 544..4752 DOFs; 3D:
    1.1e3..1.6e4)."""
    return HARD_SCENE_LEVELS[scene.dim]


def applied_load(solution) -> float:
    """|resultant of the load vector| (body force and tractions), 0 for a load-free scene."""
    return float(np.linalg.norm(solution.elasticity.nodal(solution.elasticity.F).sum(axis=1)))


def scene_finding(row: dict, solution) -> str:
    """The contact zone, force and active rows in numbers; the force against the applied load
    where the body is loaded; a failed solve says that it failed, and why."""
    if solution.status == STATUS_FAILED:
        return f"the {row['solver']} solve failed: {row['reason'] or 'no reason given'}"
    zone = contact_zone(solution)
    force = row["contact_force"]
    text = (f"contact zone [{zone[0]:.3g}, {zone[1]:.3g}], force {force:.4g}" if np.isfinite(
        zone[0]) else f"no contact, force {force:.3g}")
    text += f", {row['active_constraints']} of {row['n_constraints']} rows active"
    load = applied_load(solution)
    if load > 0 and np.isfinite(force):
        text += f", force = {force / load:.1e} of the applied load"
    return text


def uniform_meshes(scene, cell: str, levels: int) -> list:
    """The starting mesh of ``cell``'s family and its ``levels`` uniform refinements."""
    family = family_for(cell, scene.dim)
    meshes = [family.starting_mesh(scene)]
    for _ in range(levels):
        meshes.append(family.refinement(meshes[-1]).refined)
    return meshes


def force_change(scene, formulation: str, coarse_mesh, fine: float) -> float:
    """Relative change of the contact force from one uniform level coarser."""
    coarse = solve(get_formulation(formulation)(scene, coarse_mesh), FAST_SOLVER).contact_force()
    return abs(fine - coarse) / max(abs(fine), abs(coarse)) if fine or coarse else 0.0


def scene_case(name: str, cell: str = DEFAULT_CELL) -> list[dict]:
    scene = get_scene(name)
    family = family_for(cell, scene.dim)
    why = family.why_not(scene)
    if why is not None:
        return [dict(case=name, scene=name, formulation="", solver="", variant=cell, level=0,
                     status="skipped", reason=why, verdict=REFUSED, finding=why)]
    *_, coarse, mesh = uniform_meshes(scene, cell, hard_level(scene))
    variant = "" if cell == DEFAULT_CELL else cell
    records = []
    for formulation in FORMULATIONS.names():
        if FORMULATIONS.why_not(formulation, scene=scene, family=family) is not None:
            continue
        rows, sols = solve_both(name, scene, formulation, mesh, variant=variant,
                                level=hard_level(scene))
        fine = next((r["contact_force"] for r in rows if r["status"] != STATUS_FAILED), np.nan)
        change = force_change(scene, formulation, coarse, fine)
        for row, sol in zip(rows, sols, strict=True):
            row["finding"] = scene_finding(row, sol)
            row["force_change"] = change
            row["discretisation"] = ""  # a failed solve judges no discretisation
            if sol.status != STATUS_FAILED:
                row["finding"] += f"; force changed by {change:.1%} from the level before"
                row["discretisation"] = "settled" if change <= SETTLED else "unsettled"
        records += rows
    return records

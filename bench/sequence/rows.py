"""One result row per (scene, formulation, solver, estimator, strategy, level).

Column names are a public interface (docs/columns.md: the columns and their units): add new
columns, never rename.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, fields

from bench.sequence.goal import goal_of


@dataclass(frozen=True)
class ResultRow:
    scene: str
    formulation: str
    solver: str
    estimator: str
    strategy: str
    level: int
    order: int = 1  # polynomial order p of the displacements
    dim: int = 2  # of the body: 2 (triangles) or 3 (tetrahedra)
    cell: str = "tri"  # the cells' shape: tri (simplices) or quad (quadrilaterals, hexahedra)
    ndofs: int = 0
    n_elements: int = 0
    h_max: float = math.nan
    h_min: float = math.nan
    max_h_over_H: float = math.nan
    energy: float = math.nan
    contact_force: float = math.nan
    active_constraints: int = 0
    n_constraints: int = 0
    eta: float = math.nan
    eta_0: float = math.nan
    eta_geometric: float = math.nan
    eta_complementarity: float = math.nan
    eta_symmetric: float = math.nan  # the parts of a guaranteed bound (estimators.BoundTerms)
    eta_skew: float = math.nan
    eta_oscillation: float = math.nan
    eta_load: float = math.nan
    eta_negative_traction: float = math.nan
    eta_excess_shear: float = math.nan  # with Tresca friction (docs/theory.md, 17.5)
    eta_friction_complementarity: float = math.nan
    violation: float = math.nan
    dual_violation: float = math.nan
    complementarity: float = math.nan
    stationarity: float = math.nan
    iterations: int = 0
    backend: str = ""
    warm_started: bool = False
    t_assemble: float = math.nan
    t_solve: float = math.nan
    t_estimate: float = math.nan
    t_refine: float = math.nan
    status: str = ""
    reason: str = ""
    truth: str = ""
    energy_error: float = math.nan
    pressure_error: float = math.nan
    zone_error: float = math.nan
    contact_zone_start: float = math.nan
    contact_zone_end: float = math.nan
    zone_jaccard: float = math.nan  # 1 - |Z_h n Z| / |Z_h u Z| against the true zone
    # how far u_h goes through the obstacle (bench.measure.contact, docs/theory.md, 19.1)
    penetration: float = math.nan
    nodal_penetration: float = math.nan
    approach: float = math.nan
    penetration_share: float = math.nan
    friction: str = ""  # the scene's friction law (scenes.friction): none, tresca, coulomb(mu=..)
    stick_points: int = 0
    slip_points: int = 0
    stick_zone_start: float = math.nan
    stick_zone_end: float = math.nan
    stick_zone_error: float = math.nan
    shear_error: float = math.nan
    effectivity_index: float = math.nan
    effectivity_0: float = math.nan
    effectivity_geometric: float = math.nan
    effectivity_complementarity: float = math.nan
    reference_error: float = math.nan
    reference_too_coarse: bool = False
    t_error: float = math.nan
    crosscheck_status: str = ""
    crosscheck_energy_difference: float = math.nan
    crosscheck_pressure_difference: float = math.nan
    marking: str = ""
    theta: float = math.nan
    condition_estimate: float = math.nan
    active_set_changes: str = ""
    cycled: bool = False
    safeguard: str = ""
    inf_sup: float = math.nan
    pressure_oscillation: float = math.nan
    t_diagnostics: float = math.nan
    # the iterate's error components and the work of its solve (docs/theory.md, section 18)
    eta_disc: float = math.nan
    eta_lin: float = math.nan
    eta_alg: float = math.nan
    eta_total: float = math.nan
    effectivity_total: float = math.nan
    stopping: str = "fixed"  # the stopping rule of the solves: fixed or adaptive
    stopped_early: bool = False  # the adaptive rule ended it before the fixed tolerances
    newton_steps: int = 0
    krylov_iterations: int = 0
    # the run's quantity of interest (bench.sequence.goal, docs/theory.md section 20)
    goal: str = ""
    goal_estimator: str = ""
    goal_status: str = ""  # why the goal has no estimate on this level ("" if it has one)
    qoi: float = math.nan
    qoi_exact: float = math.nan
    qoi_true: float = math.nan
    qoi_error: float = math.nan
    qoi_relative_error: float = math.nan
    qoi_estimate: float = math.nan
    qoi_effectivity: float = math.nan
    qoi_sign_right: bool = False
    qoi_residual_part: float = math.nan
    qoi_contact_part: float = math.nan
    qoi_guaranteed: bool = False
    qoi_lower: float = math.nan
    qoi_upper: float = math.nan
    qoi_interval_holds: bool = False  # qoi_lower <= qoi_true <= qoi_upper
    dual_dofs: int = 0
    t_goal: float = math.nan
    scene_parameters: str = ""  # a sweep's scene parameters, "name=value:name=value"
    formulation_options: str = ""  # a sweep's formulation options, the same way
    sequence_key: str = ""  # hash of everything that determines the sequence
    sequence_end: str = ""  # why it ended: budget, max_levels, memory, failed, target, interrupted
    run_id: str = ""
    commit: str = ""
    python: str = ""
    versions: str = ""
    machine: str = ""

    def as_dict(self) -> dict:
        return asdict(self)


COLUMNS = [f.name for f in fields(ResultRow)]
# identity of a combination (the sweep labels are empty outside sweeps)
KEYS = ["scene", "formulation", "solver", "estimator", "strategy", "order", "cell",
        "stopping", "goal", "scene_parameters", "formulation_options"]
LABELS = ["scene_parameters", "formulation_options"]
# sequence_end of a complete sequence; INTERRUPTED (or no end at all) marks one cut short
FINISHED = ("budget", "max_levels", "memory", "failed", "skipped", "target")
INTERRUPTED = "interrupted"
# the phases of a level whose wall times add up to the level's time
PHASE_TIMES = ["t_assemble", "t_solve", "t_estimate", "t_goal", "t_refine"]


def identity_columns(scene: str, formulation: str, solver: str, estimator: str, config,
                     run: dict | None = None, dim: int = 2) -> dict:
    """The columns that name a sequence: the combination, its marking (``config`` is a
    ``bench.sequence.loop.LoopConfig``) and the run's identity, sweep labels and provenance
    (``run``) and the body's dimension."""
    return dict(scene=scene, formulation=formulation, solver=solver, estimator=estimator,
                strategy=config.strategy, order=config.order, dim=dim, cell=config.cell,
                stopping=config.stopping, goal=goal_of(config) or "",
                marking=config.marking,
                theta=config.theta,
                **(run or {}))


def name_parts(row) -> list:
    """The values of KEYS of a row, the default cell left out: what names its files (so that
    a triangle sequence keeps the names it had before cells were an axis)."""
    return [getattr(row, k) for k in KEYS if not (k == "cell" and getattr(row, k) == "tri")
            and not (k == "stopping" and getattr(row, k) in ("fixed", ""))
            and not (k == "goal" and not getattr(row, k))]


def with_labels(frame):
    """A result table with the sweep label columns present and empty strings for missing
    labels (rows of older tables; their order is 1, their cells triangles), so that grouping
    by KEYS keeps every row."""
    frame = frame.copy()
    frame["order"] = (frame["order"].fillna(1).astype(int) if "order" in frame else 1)
    frame["dim"] = (frame["dim"].fillna(2).astype(int) if "dim" in frame else 2)
    frame["cell"] = (frame["cell"].astype(object).fillna("tri").astype(str) if "cell" in frame
                     else "tri")
    frame["stopping"] = (frame["stopping"].astype(object).fillna("fixed").replace("", "fixed")
                         .astype(str) if "stopping" in frame else "fixed")
    for column in LABELS + ["goal", "sequence_key", "sequence_end"]:
        frame[column] = (frame[column].astype(object).fillna("").astype(str) if column in frame
                         else "")
    return frame


def level_time(row: ResultRow) -> float:
    """Wall time of a level: the sum of its phases (a phase that did not run counts 0)."""
    return float(sum(t for t in (getattr(row, c) for c in PHASE_TIMES) if math.isfinite(t)))


def phase_time(frame):
    """Per row of a result table (a DataFrame), the sum of its phase times."""
    return frame[PHASE_TIMES].fillna(0).sum(axis=1)

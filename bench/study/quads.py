"""The seed's own discretisation, measured: Q1/Q2 on hierarchical quadrilateral meshes (uniform
and adaptive with hanging nodes), the VI and the mixed method with lambda_H one or two levels
coarser, the seed's residual estimator, errors against exact solutions or the P3 references
(docs/theory.md, section 15). ``python -m bench study --cell quad`` runs it.

A scene runs on quadrilaterals when its starting mesh is a tensor grid (every built-in 2D
scene): the grid's lines give the root cells, so no second scene definition is needed.
"""

from __future__ import annotations

import time
from dataclasses import asdict, dataclass

import numpy as np
import pandas as pd
from skfem import Basis, ElementQuad0

from bench.measure.discretisation_error import energy_density
from bench.measure.fields import GradientField
from bench.measure.nonnested import energy_difference
from bench.measure.quad_fields import quad_gradient_field
from bench.measure.slope import fit_slope
from bench.sequence.marking import mark
from estimators.quad_residual import quad_residual_estimate
from formulations.cells import family_for
from formulations.cells.quadrilateral import tensor_axes
from formulations.elasticity import count_free_dofs
from formulations.hex_vi import hex_mesh, solve_hex_vi
from formulations.quad_mixed import solve_quad_mixed
from formulations.quad_vi import solve_quad_vi
from scenes import get_scene
from scenes.quad_hierarchy import QuadHierarchy

# the quadrilateral methods: name -> (solve, keyword arguments)
METHODS = {"vi": (solve_quad_vi, {}), "mixed": (solve_quad_mixed, {"levels_up": 1}),
           "mixed-H4": (solve_quad_mixed, {"levels_up": 2})}
EXACT_ORDER = 8  # quadrature of the exact error: f of free-boundary jumps inside cells


@dataclass(frozen=True)
class QuadRow:
    """One level of a quadrilateral sequence."""

    scene: str
    method: str
    order: int
    strategy: str
    level: int
    ndofs: int
    hanging_nodes: int
    eta: float
    eta_0: float
    energy_error: float
    effectivity_index: float
    contact_force: float
    energy: float
    t_solve: float
    t_estimate: float
    status: str


def tensor_grid(scene) -> tuple[np.ndarray, np.ndarray]:
    """The grid lines of a scene whose starting mesh is a 2D tensor grid of triangles (the
    quadrilateral family's root cells); ValueError for any other mesh."""
    why = family_for("quad", 2).why_no_mesh(scene)
    if why is not None:
        raise ValueError(why)
    xs, ys = tensor_axes(scene)
    return xs, ys


def exact_error(scene, solution) -> float:
    """||u - u_h|| against the scene's exact solution, by quadrature on the cells."""
    elasticity = solution.elasticity
    basis = Basis(elasticity.basis.mesh, ElementQuad0(), intorder=EXACT_ORDER)
    x = np.asarray(basis.global_coordinates())
    quadrature = Basis(elasticity.basis.mesh, elasticity.basis.elem, intorder=EXACT_ORDER)
    grad = quadrature.interpolate(solution.u).grad - scene.exact.gradient(x)
    return float(np.sqrt((energy_density(grad, *elasticity.lame) * basis.dx).sum()))


def judge(scene, reference: GradientField | None):
    """error(solution): exact for a scene with an exact solution, else against ``reference``
    (None: not measured)."""
    if scene.exact is not None:
        return lambda solution: exact_error(scene, solution)
    if reference is None:
        return lambda solution: float("nan")
    return lambda solution: energy_difference(
        quad_gradient_field(solution.elasticity.basis, solution.u), reference,
        solution.elasticity.lame)


def quad_sequence(scene_name: str, method: str, order: int, strategy: str, max_dofs: int,
                  reference: GradientField | None = None, theta: float = 0.5) -> list[QuadRow]:
    """Solve, estimate, mark (Doerfler) and refine on quadrilaterals until the next level
    would pass ``max_dofs``."""
    scene = get_scene(scene_name)
    hierarchy = QuadHierarchy.from_tensor(*tensor_grid(scene))
    solve, options = METHODS[method]
    error_of, rows = judge(scene, reference), []
    for level in range(60):
        if count_free_dofs(scene, hierarchy.mesh(), order) > max_dofs:  # before anything is built
            break
        start = time.perf_counter()
        solution = solve(scene, hierarchy, order, **options)
        t_solve = time.perf_counter() - start
        start = time.perf_counter()
        estimate = quad_residual_estimate(scene, solution)
        t_estimate = time.perf_counter() - start
        error = error_of(solution)
        rows.append(QuadRow(scene_name, method, order, strategy, level,
                            solution.elasticity.ndofs, hierarchy.hanging()[0].size,
                            estimate.eta, estimate.eta_0, error, estimate.eta / error,
                            solution.contact_force, solution.energy, t_solve, t_estimate,
                            solution.status))
        if solution.status == "failed":
            break
        if strategy == "uniform":
            hierarchy = hierarchy.refined()
        else:
            hierarchy = hierarchy.refined(mark(estimate.indicators, "doerfler", theta))
    return rows


def hex_error(scene, solution) -> float:
    """||u - u_h|| on hexahedra against the scene's exact solution (NaN without one)."""
    if scene.exact is None:
        return float("nan")
    basis = Basis(solution.elasticity.mesh, solution.elasticity.basis.elem, intorder=6)
    x = np.asarray(basis.global_coordinates())
    grad = basis.interpolate(solution.u).grad - scene.exact.gradient(x)
    return float(np.sqrt((energy_density(grad, *solution.elasticity.lame) * basis.dx).sum()))


def hex_sequence(scene_name: str, max_dofs: int) -> list[QuadRow]:
    """Q1 on hexahedra, the VI, uniform refinement of the scene's grid of cubes until the
    next level would pass ``max_dofs`` (no estimator on hexahedra yet: eta is NaN)."""
    scene, rows = get_scene(scene_name), []
    for level in range(20):
        mesh = hex_mesh(scene, level)
        if 3 * mesh.p.shape[1] > max_dofs:  # at least the free DOFs: no level over budget
            break
        start = time.perf_counter()
        solution = solve_hex_vi(scene, mesh)
        t_solve = time.perf_counter() - start
        error = hex_error(scene, solution)
        rows.append(QuadRow(scene_name, "vi", 1, "uniform", level, solution.elasticity.ndofs,
                            0, float("nan"), float("nan"), error, float("nan"),
                            solution.contact_force, solution.energy, t_solve, 0.0,
                            solution.status))
        if solution.status == "failed":
            break
    return rows


def slopes(table: pd.DataFrame, column: str, last: int = 4) -> pd.DataFrame:
    """Per sequence, the slope of log(column) against log(ndofs) over its last ``last``
    levels, and over all levels (``bench.measure.slope``)."""
    out = []
    keys = ["scene", "method", "order", "strategy"]
    for key, group in table.groupby(keys, sort=False):
        group = group[np.isfinite(group[column]) & (group[column] > 0)]
        if len(group) < 3:
            continue
        x, y = group["ndofs"].to_numpy(float), group[column].to_numpy(float)
        tail = slice(-min(last, len(group)), None)
        out.append(dict(zip(keys, key, strict=True), levels=len(group),
                        dofs=f"{group['ndofs'].iloc[0]}..{group['ndofs'].iloc[-1]}",
                        slope_all=fit_slope(x, y).slope,
                        slope_last=fit_slope(x[tail], y[tail]).slope))
    return pd.DataFrame(out)


def as_frame(rows: list[QuadRow]) -> pd.DataFrame:
    return pd.DataFrame([asdict(r) for r in rows])


@dataclass(frozen=True)
class QuadStudy:
    """What ``python -m bench study --cell quad`` runs: every scene x method x order x
    strategy on quadrilaterals, to the budgets, errors against exact solutions or the cached
    P3 references of ``reference_dofs`` DOFs."""

    scenes: tuple[str, ...] = ("paper", "free-boundary", "hertz")
    methods: tuple[str, ...] = tuple(METHODS)
    orders: tuple[int, ...] = (1,)
    strategies: tuple[str, ...] = ("uniform", "adaptive")
    uniform_max_dofs: int = 2_100_000
    adaptive_max_dofs: int = 1_000_000
    reference_dofs: int | None = 200_000


def reference_field(scene_name: str, reference_dofs: int | None) -> GradientField | None:
    """The P3 reference of a scene without an exact solution, from the cache (built if
    missing); None without a budget or for a scene with an exact solution."""
    scene = get_scene(scene_name)
    if scene.exact is not None or reference_dofs is None:
        return None
    from bench.truth.cache import load_or_build  # only studies against references need it

    reference = load_or_build(scene, reference_dofs)
    return GradientField.from_dofs(reference.mesh, reference.order, reference.u)


def run_quad_study(study: QuadStudy, on_sequence=None) -> pd.DataFrame:
    """Every sequence of ``study``; ``on_sequence(rows)`` after each."""
    rows = []
    for scene in study.scenes:
        reference = reference_field(scene, study.reference_dofs)
        for method in study.methods:
            for order in study.orders:
                for strategy in study.strategies:
                    budget = (study.uniform_max_dofs if strategy == "uniform"
                              else study.adaptive_max_dofs)
                    sequence = quad_sequence(scene, method, order, strategy, budget,
                                             reference)
                    rows += sequence
                    if on_sequence is not None:
                        on_sequence(sequence)
    return as_frame(rows)


def write_quad_report(table: pd.DataFrame, folder, command: str = "",
                      fig1_dofs: int = 20000) -> str:
    """REPORT/quads.md (the slopes of error and eta, and every level) and quads.csv."""
    from pathlib import Path

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    table.to_csv(folder / "quads.csv", index=False)
    error, eta = slopes(table, "energy_error"), slopes(table, "eta")
    merged = error.merge(eta, on=["scene", "method", "order", "strategy", "levels", "dofs"],
                         suffixes=("_error", "_eta"))
    text = ["# Quadrilaterals: the seed's own discretisation", "",
            f"`{command}`" if command else "", "",
            "Slopes of the energy error and of eta against the DOFs N (least squares over all "
            "levels and over the last four); N^(-1/4) is the seed's \"nearly O(h^1/2)\", "
            "N^(-1/2) is O(h).", "",
            merged.to_markdown(index=False, floatfmt=".3f"), "",
            "## Every level", "",
            table.to_markdown(index=False, floatfmt=".4g"), ""]
    text[6:6] = write_quad_figures(table, folder, fig1_dofs)
    (folder / "quads.md").write_text("\n".join(text))
    return str(folder / "quads.md")


def write_quad_figures(table: pd.DataFrame, folder, fig1_dofs: int = 20000) -> list[str]:
    """The seed's Fig. 1 (on its first scene) and Fig. 2 (per scene) as PNGs in
    FOLDER/figures; the Markdown lines that show them."""
    from bench.study.quad_figures import estimated_error, mesh_and_stress

    figures = folder / "figures"
    figures.mkdir(exist_ok=True)
    lines = []
    scenes = list(dict.fromkeys(table["scene"]))
    if scenes:
        mesh_and_stress(scenes[0], fig1_dofs).savefig(figures / "quad-fig1.png", dpi=110)
        lines += [f"![Fig. 1, Q1: {scenes[0]}](figures/quad-fig1.png)", ""]
    for scene in scenes:
        name = f"quad-fig2-{scene}.png"
        estimated_error(table, scene).savefig(figures / name, dpi=110)
        lines += [f"![Fig. 2: {scene}](figures/{name})", ""]
    return lines


def write_hex_report(table: pd.DataFrame, folder, command: str = "") -> str:
    """REPORT/hexes.md (the error's slopes and every level) and hexes.csv."""
    from pathlib import Path

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    table.to_csv(folder / "hexes.csv", index=False)
    text = ["# Hexahedra: Q1, uniform", "", f"`{command}`" if command else "", "",
            "Slopes of the energy error against the DOFs N (least squares); O(h) is N^(-1/3) in "
            "3D.", "", slopes(table, "energy_error").to_markdown(index=False, floatfmt=".3f"),
            "", table.dropna(axis=1, how="all").to_markdown(index=False, floatfmt=".4g"), ""]
    (folder / "hexes.md").write_text("\n".join(text))
    return str(folder / "hexes.md")

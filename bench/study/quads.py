"""Q1 on hexahedra, uniform, the VI (``formulations.hex_vi``): errors against the scene's exact
solution. ``python -m bench study --cell hex`` runs it (docs/theory.md, section 15).
"""

from __future__ import annotations

import time
from dataclasses import asdict, dataclass

import numpy as np
import pandas as pd
from skfem import Basis

from bench.measure.discretisation_error import energy_density
from bench.measure.slope import fit_slope
from formulations.hex_vi import hex_mesh, solve_hex_vi
from scenes import get_scene


@dataclass(frozen=True)
class QuadRow:
    """One level of a hexahedral sequence."""

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

"""The seed's Figures 1 and 2, drawn from a study's results: the adaptive mesh of its setup
(the mixed method, residual estimator, lowest order) with its hanging nodes and the von Mises
stress on the deformed body (Fig. 1, from the level's artifact), and the estimated and true
error under uniform and adaptive refinement with their slopes (Fig. 2, from the rows)
(docs/theory.md, section 15). ``matplotlib.figure.Figure`` objects, no pyplot state."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.collections import PolyCollection
from matplotlib.figure import Figure

from bench.matrix.artifacts import level_artifact_path, load_artifact
from bench.measure.slope import fit_slope
from bench.report.figures import VON_MISES_PERCENTILE, _slope_triangle, cell_polygons
from bench.sequence.rows import with_labels
from formulations import STATUS_OK
from scenes.registry import scene_dim

SEED_SETUP = {"formulation": "mixed", "formulation_options": "", "estimator": "residual"}
FIG1_DOFS = 20000  # Fig. 1: the last adaptive level within this many DOFs


def seed_sequence(table: pd.DataFrame, scene: str, strategy: str) -> pd.DataFrame:
    """The rows of the seed's setup (``SEED_SETUP``, lowest order) on ``scene`` refined by
    ``strategy``; else of the first formulation the study ran."""
    rows = with_labels(table[(table["scene"] == scene) & (table["status"] == STATUS_OK)])
    rows = rows[rows["order"] == rows["order"].min()] if len(rows) else rows
    mine = rows
    for column, value in SEED_SETUP.items():
        if (mine[column] == value).any():
            mine = mine[mine[column] == value]
    first = mine[["formulation", "formulation_options"]].drop_duplicates().head(1)
    mine = mine.merge(first, on=["formulation", "formulation_options"])
    return mine[mine["strategy"] == strategy].sort_values("ndofs")


def hanging_vertices(p: np.ndarray, t: np.ndarray) -> np.ndarray:
    """The vertices that lie at the midpoint of another cell's edge (a 1-irregular mesh's
    hanging nodes; none on a conforming mesh). ``t`` lists each cell's corners in order."""
    corners = p[:, t]                                        # (2, k, n)
    midpoints = 0.5 * (corners + np.roll(corners, -1, axis=1)).reshape(2, -1)
    scale = np.abs(p).max() + 1.0

    def points(x: np.ndarray) -> np.ndarray:  # one record per point, rounded alike
        x = np.ascontiguousarray(np.round(x.T / scale, 10))
        return x.view([("", x.dtype)] * x.shape[1]).ravel()

    return np.flatnonzero(np.isin(points(p), points(midpoints)))


def mesh_and_stress(artifact: dict, title: str) -> Figure:
    """Fig. 1: the mesh (hanging nodes in red) and von Mises on the deformed body."""
    p, t, u = artifact["p"], artifact["t"], artifact["u"]
    fig = Figure(figsize=(11, 5))
    left, right = fig.subplots(1, 2)
    left.add_collection(PolyCollection(cell_polygons(p, t), facecolors="none", edgecolors="k",
                                       linewidths=0.2))
    hanging = p[:, hanging_vertices(p, t)]
    left.plot(hanging[0], hanging[1], "r.", markersize=2,
              label=f"{hanging.shape[1]} hanging nodes")
    left.set_title(f"{title}: {int(artifact['ndofs'])} DOFs, {t.shape[1]} cells", fontsize=9)
    left.legend(loc="upper right", fontsize=7)
    vm = artifact["von_mises"]
    top = np.percentile(vm, VON_MISES_PERCENTILE)
    scale = 0.1 * np.ptp(p, axis=1).max() / max(np.abs(u).max(), 1e-300)
    scale = 10 ** np.floor(np.log10(scale)) if scale < 1 else 1.0
    art = right.add_collection(PolyCollection(cell_polygons(p + scale * u, t),
                                              array=np.minimum(vm, top), cmap="viridis",
                                              edgecolors="face", linewidths=0.2))
    fig.colorbar(art, ax=right, label=f"von Mises (clipped at its {VON_MISES_PERCENTILE:g}th "
                                      f"percentile = {top:.4g})")
    right.set_title(f"von Mises on the deformed body, displacement x {scale:g}", fontsize=9)
    for ax in (left, right):
        ax.autoscale()
        ax.set_aspect("equal")
    fig.tight_layout()
    return fig


def estimated_error(table: pd.DataFrame, scene: str) -> Figure:
    """Fig. 2: eta and the error against the DOFs, uniform and adaptive, of the seed's setup,
    with the fitted slopes in the legend and the slopes of the seed's O(h^1/2) and of O(h)
    drawn (-1/4 and -1/2 in 2D, -1/6 and -1/3 in 3D: h is N^(-1/d))."""
    fig = Figure(figsize=(6.5, 5))
    ax = fig.subplots()
    name = ""
    for strategy, style in (("uniform", "o-"), ("adaptive", "s-")):
        group = seed_sequence(table, scene, strategy)
        for column, label, alpha in (("eta", "eta", 1.0), ("energy_error", "error", 0.5)):
            good = group[np.isfinite(group[column]) & (group[column] > 0)]
            if len(good) < 2:
                continue
            name = sequence_name(good.iloc[0])
            slope = fit_slope(good["ndofs"], good[column]).slope
            ax.loglog(good["ndofs"], good[column], style, markersize=3, alpha=alpha,
                      label=f"{label}, {strategy} (slope {slope:.2f})")
    rows = seed_sequence(table, scene, "uniform")
    if len(rows):
        x0, y0 = rows["ndofs"].min() * 3, rows["eta"].max() / 3
        d = scene_dim(scene) or 2
        _slope_triangle(ax, x0, y0, -1 / (2 * d), f"-1/{2 * d}: O(h^1/2)")
        _slope_triangle(ax, x0, y0 / 10, -1 / d, f"-1/{d}: O(h)")
    ax.set_xlabel("DOFs N")
    ax.set_ylabel("energy norm")
    ax.set_title(f"{scene}, {name}: estimated and true error", fontsize=9)
    ax.legend(fontsize=7, loc="lower left")
    fig.tight_layout()
    return fig


def sequence_name(row) -> str:
    options = f":{row['formulation_options']}" if row["formulation_options"] else ""
    return f"{row['formulation']}{options}, {row['estimator']}, {row['cell']} p{row['order']}"


def write_seed_figures(table: pd.DataFrame, results: str | Path, folder: Path,
                       fig1_dofs: int = FIG1_DOFS) -> list[str]:
    """Fig. 1 (on the first scene, from the artifacts in ``results``) and Fig. 2 (per scene)
    as PNGs in ``folder``; their file names."""
    names = []
    scenes = list(dict.fromkeys(table["scene"]))
    adaptive = seed_sequence(table, scenes[0], "adaptive") if scenes else table.head(0)
    within = adaptive[adaptive["ndofs"] <= fig1_dofs]
    artifact = (load_artifact(level_artifact_path(results, next(within.tail(1).itertuples())))
                if len(within) else None)
    if artifact is not None and artifact["p"].shape[0] == 2:  # Fig. 1 is a plane picture
        title = f"{scenes[0]}, {sequence_name(within.iloc[-1])}, adaptive"
        mesh_and_stress(artifact, title).savefig(folder / "seed-fig1.png", dpi=110)
        names.append("seed-fig1.png")
    for scene in scenes:
        estimated_error(table, scene).savefig(folder / f"seed-fig2-{scene}.png", dpi=110)
        names.append(f"seed-fig2-{scene}.png")
    return names

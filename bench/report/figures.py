"""Report figures: ``matplotlib.figure.Figure`` objects (no pyplot state, no global backend).
Colour = formulation, line style = estimator, marker = strategy, the same in every figure,
each drawn from a cycle in the order of the registries. Each function returns a Figure or None
when its data are missing."""

from __future__ import annotations

import textwrap

import numpy as np
import pandas as pd
from matplotlib.collections import LineCollection, PolyCollection
from matplotlib.figure import Figure
from matplotlib.tri import Triangulation

from bench.sequence.loop import STRATEGIES
from bench.sequence.rows import phase_time
from estimators import estimator_names
from formulations import STATUS_OK, formulation_names
from formulations.contact import facet_coordinates

COLOUR_CYCLE = [f"C{k}" for k in range(10)]
STYLE_CYCLE = ["-", "--", ":", "-."]
MARKER_CYCLE = ["s", "o", "^", "v", "D"]
VON_MISES_PERCENTILE = 99.0


def _from_cycle(name: str, names: list[str], cycle: list[str]) -> str:
    """The cycle's entry at ``name``'s place among ``names`` (unknown names after them)."""
    index = names.index(name) if name in names else len(names) + sum(map(ord, str(name)))
    return cycle[index % len(cycle)]


def colour(formulation: str) -> str:
    return _from_cycle(formulation, formulation_names(), COLOUR_CYCLE)


def line_style(estimator: str) -> str:
    return _from_cycle(estimator, estimator_names(), STYLE_CYCLE)


def marker(strategy: str) -> str:
    return _from_cycle(strategy, list(STRATEGIES), MARKER_CYCLE)


def _line(ax, group: pd.DataFrame, x: str, y: str, key: tuple, label: bool = True):
    formulation, estimator, strategy = key[:3]
    ok = group[(group["status"] == STATUS_OK) & (group[y] > 0)].sort_values(x)
    if ok.empty:
        return
    ax.loglog(ok[x], ok[y], color=colour(formulation), linestyle=line_style(estimator),
              marker=marker(strategy), markersize=3, linewidth=1,
              label=_name(key) if label else None)


def _slope_triangle(ax, x0: float, y0: float, slope: float, text: str):
    x1 = x0 * 10
    y1 = y0 * 10**slope
    ax.loglog([x0, x1, x1, x0], [y0, y0, y1, y0], color="k", linewidth=0.7)
    ax.annotate(text, (x1, np.sqrt(y0 * y1)), fontsize=7, xytext=(3, 0),
                textcoords="offset points")


def _keys(table):
    """Groups of one sequence's levels: formulation, estimator, strategy (and the order and
    the cells where the table has several)."""
    return table.groupby(["formulation", "estimator", "strategy", *_order_key(table)],
                         sort=True)


def _order_key(table) -> list[str]:
    """The sequence columns beyond the combination that vary in ``table``: order, cell."""
    return [c for c in ("order", "cell") if c in table and table[c].nunique() > 1]


def _name(key: tuple) -> str:
    """'formulation/estimator/strategy', with '/P<order>' and '/<cell>' when the key carries
    them."""
    return "/".join(str(k) for k in key[:3]) + "".join(
        f"/P{k}" if isinstance(k, (int, np.integer)) else f"/{k}" for k in key[3:])


def convergence(table: pd.DataFrame):
    """Error and eta against ndofs with O(h^1/2) and O(h) triangles (the paper's Figure 2)."""
    fig = Figure(figsize=(11, 4.5))
    axes = fig.subplots(1, 2, sharex=True)
    has_error = table["energy_error"].gt(0).any()
    for key, group in _keys(table):
        _line(axes[0], group, "ndofs", "energy_error", key)
        _line(axes[1], group, "ndofs", "eta", key, label=not has_error)
    for ax, name in zip(axes, ("energy-norm error ||u - u_h||", "estimator eta"), strict=True):
        ax.set_xlabel("ndofs")
        ax.set_title(name, fontsize=10)
        ax.grid(True, which="both", alpha=0.3)
        lines = ax.get_lines()
        if lines:
            y = np.concatenate([line.get_ydata() for line in lines])
            x = np.concatenate([line.get_xdata() for line in lines])
            _slope_triangle(ax, x.min() * 3, y.max() / 2, -0.25, "-1/4: O(h^1/2)")
            _slope_triangle(ax, x.min() * 3, y.min() * 4, -0.5, "-1/2: O(h)")
    if not has_error:
        axes[0].text(0.5, 0.5, "no error measured\n(no exact solution or reference)",
                     ha="center", va="center", transform=axes[0].transAxes)
    handles = axes[0].get_legend_handles_labels()[0] or axes[1].get_legend_handles_labels()[0]
    if handles:
        fig.legend(loc="center right", fontsize=7)
    fig.tight_layout(rect=(0, 0, 0.8, 1))
    return fig


def effectivity(table: pd.DataFrame):
    if not table["effectivity_index"].gt(0).any():
        return None
    fig = Figure(figsize=(8, 4))
    ax = fig.subplots()
    for key, group in _keys(table):
        ok = group[group["effectivity_index"] > 0].sort_values("ndofs")
        look = dict(color=colour(key[0]), linestyle=line_style(key[1]),
                     marker=marker(key[2]), markersize=3, linewidth=1)
        ax.semilogx(ok["ndofs"], ok["effectivity_index"], label=_name(key), **look)
        coarse = ok[ok["reference_too_coarse"].astype(bool)]
        ax.semilogx(coarse["ndofs"], coarse["effectivity_index"], "x", color="k", markersize=5)
    ax.axhline(1.0, color="k", linewidth=0.6)
    ax.set_yscale("log")  # coarse levels can be off by 100x and would flatten the rest
    ax.set_xlabel("ndofs")
    ax.set_ylabel("eta / ||u - u_h||")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=6, ncol=2)
    fig.tight_layout()
    return fig


def work_precision(table: pd.DataFrame):
    """Error (or eta) against cumulative wall time and against the solve time per level."""
    y = "energy_error" if table["energy_error"].gt(0).any() else "eta"
    fig = Figure(figsize=(11, 4.2))
    axes = fig.subplots(1, 2, sharey=True)
    for key, group in table.groupby(["formulation", "solver", "estimator", "strategy",
                                     *_order_key(table)]):
        group = group[group["status"] == STATUS_OK].sort_values("level")
        times = phase_time(group)
        look = dict(color=colour(key[0]), linestyle=line_style(key[2]),
                     marker=marker(key[3]), markersize=3, linewidth=1)
        axes[0].loglog(times.cumsum(), group[y], label="/".join(map(str, key)), **look)
        axes[1].loglog(group["t_solve"], group[y], **look)
    axes[0].set_xlabel("cumulative wall time of the sequence [s]")
    axes[1].set_xlabel("solve time of the level [s]")
    axes[0].set_ylabel(y)
    for ax in axes:
        ax.grid(True, which="both", alpha=0.3)
    axes[0].legend(fontsize=6)
    fig.tight_layout()
    return fig


def cell_polygons(p: np.ndarray, t: np.ndarray) -> np.ndarray:
    """The cells as polygons (n_cells, corners, 2), triangles and quadrilaterals alike (a
    hanging node is a vertex of its fine cells and lies on the coarse cell's edge)."""
    return np.transpose(p[:2, t], (2, 1, 0))


def meshes(artifacts: dict):
    """Final adaptive mesh per formulation/estimator (the paper's Figure 1b)."""
    items = sorted((k, v) for k, v in artifacts.items() if k[2] == "adaptive")
    if not items:
        return None
    cols = min(3, len(items))
    rows = int(np.ceil(len(items) / cols))
    fig = Figure(figsize=(4 * cols, 4 * rows))
    axes = fig.subplots(rows, cols, squeeze=False)
    for ax in axes.ravel():
        ax.set_axis_off()
    for ax, (key, data) in zip(axes.ravel(), items, strict=False):
        ax.add_collection(PolyCollection(cell_polygons(data["p"], data["t"]), facecolors="none",
                                         edgecolors=colour(key[0]), linewidths=0.15))
        ax.autoscale_view()
        order = f"/P{key[3]}" if len(key) > 3 and key[3] != 1 else ""
        cell = f"/{key[4]}" if len(key) > 4 and key[4] != "tri" else ""
        ax.set_title(f"{key[0]}/{key[1]}{order}{cell}: {int(data['ndofs'])} DOFs", fontsize=9)
        ax.set_aspect("equal")
    fig.tight_layout()
    return fig


def deformed(data: dict, title: str):
    """Deformed body coloured by von Mises stress (the paper's Figure 1a), colour scale clipped
    at the VON_MISES_PERCENTILE-th percentile (the clamped corners are singular)."""
    if data is None:
        return None
    p, u = data["p"], data["u"]
    size = np.ptp(p, axis=1).max()
    scale = 0.1 * size / max(np.abs(u).max(), 1e-300)
    scale = 10 ** np.floor(np.log10(scale)) if scale < 1 else 1.0
    vm = data["von_mises"]
    top = np.percentile(vm, VON_MISES_PERCENTILE)
    fig = Figure(figsize=(6, 5))
    ax = fig.subplots()
    art = PolyCollection(cell_polygons(p + scale * u, data["t"]), array=np.minimum(vm, top),
                         cmap="viridis", edgecolors="face", linewidths=0.1)
    art.set_clim(0, top)
    ax.add_collection(art)
    ax.autoscale_view()
    fig.colorbar(art, ax=ax, label=f"von Mises stress (clipped at its "
                                   f"{VON_MISES_PERCENTILE:g}th percentile = {top:.4g})")
    ax.set_title(f"{title}, displacement x {scale:g}", fontsize=9)
    ax.set_aspect("equal")
    fig.tight_layout()
    return fig


def pressures(artifacts: dict, reference_curve=None):
    """lambda_h along Gamma_C per formulation (adaptive, first estimator), zone ends marked."""
    chosen = {}
    for key, data in sorted(artifacts.items()):
        if key[2] == "adaptive" and key[0] not in chosen:
            chosen[key[0]] = data
    if not chosen:
        return None
    fig = Figure(figsize=(8, 4))
    ax = fig.subplots()
    for formulation, data in chosen.items():
        s = facet_coordinates(data["trace_coordinate"],
                              np.linspace(0, 1, data["pressure"].shape[1]))
        segments = np.stack([s, data["pressure"]], axis=-1)
        ax.add_collection(LineCollection(segments, colors=colour(formulation), linewidths=1,
                                         label=f"{formulation} ({int(data['ndofs'])} DOFs)"))
        for end in data["zone"]:
            if np.isfinite(end):
                ax.axvline(end, color=colour(formulation), linewidth=0.6, linestyle=":")
    if reference_curve is not None:
        s, values, label = reference_curve
        ax.plot(s, values, "k--", linewidth=1, label=label)
    ax.autoscale()
    zones = np.array([data["zone"] for data in chosen.values()], dtype=float)
    if np.isfinite(zones).any():  # zoom on the contact zone(s)
        start, end = np.nanmin(zones[:, 0]), np.nanmax(zones[:, 1])
        ax.set_xlim(start - 0.5 * (end - start), end + 0.5 * (end - start))
    ax.set_xlabel("contact coordinate")
    ax.set_ylabel("contact pressure lambda_h")
    ax.legend(fontsize=7)
    ax.grid(True, alpha=0.3)
    fig.tight_layout()
    return fig


def scene_picture(scene):
    """Geometry, boundary parts and the obstacle of a scene (its initial mesh)."""
    mesh = scene.mesh
    fig = Figure(figsize=(5, 4.5))
    ax = fig.subplots()
    ax.triplot(Triangulation(mesh.p[0], mesh.p[1], mesh.t.T), color="0.85", linewidth=0.5)
    for facets, col, name in ((scene.dirichlet_facets(), "tab:red", "Gamma_D (clamped)"),
                              (scene.contact_facets(), "tab:blue", "Gamma_C (contact)"),
                              (scene.neumann_facets(), "0.4", "Gamma_N (traction)")):
        pts = mesh.p[:, mesh.facets[:, facets]]  # (2, 2, n)
        ax.add_collection(LineCollection(np.transpose(pts, (2, 1, 0)), colors=col,
                                         linewidths=2.5, label=name))
    contact = scene.contact_facets()
    x = scene.facet_points(contact, np.linspace(0, 1, 21)).reshape(2, -1)
    order = np.argsort(scene.contact_coordinate(x))
    x = x[:, order]
    a, b = mesh.p[:, mesh.facets[0, contact[0]]], mesh.p[:, mesh.facets[1, contact[0]]]
    tangent = (b - a) / np.linalg.norm(b - a)
    normal = np.array([tangent[1], -tangent[0]])
    if normal @ (x.mean(axis=1) - mesh.p.mean(axis=1)) < 0:
        normal = -normal
    obstacle = x + normal[:, None] * scene.gap(x)[None, :]
    ax.plot(obstacle[0], obstacle[1], "k-", linewidth=1.5, label="obstacle (x + g(x) n)")
    ax.set_aspect("equal")
    ax.legend(fontsize=7, loc="upper right")
    ax.set_title(textwrap.fill(scene.description, 60), fontsize=8)
    fig.tight_layout()
    return fig

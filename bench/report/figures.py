"""Report figures: ``matplotlib.figure.Figure`` objects (no pyplot state, no global backend).
Colour = formulation, line style = estimator, marker = strategy, the same in every figure,
each drawn from a cycle in the order of the registries. Each function returns a Figure or None
when its data are missing."""

from __future__ import annotations

import textwrap

import numpy as np
from matplotlib.collections import LineCollection, PolyCollection
from matplotlib.figure import Figure
from matplotlib.tri import Triangulation

from bench.sequence.loop import STRATEGIES
from estimators import estimator_names
from formulations import formulation_names
from formulations.cells.base import vertex_diameters
from formulations.contact.reference_facets import facet_coordinates

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


def _slope_triangle(ax, x0: float, y0: float, slope: float, text: str):
    x1 = x0 * 10
    y1 = y0 * 10**slope
    ax.loglog([x0, x1, x1, x0], [y0, y0, y1, y0], color="k", linewidth=0.7)
    # on a white box above the data, so that no line crosses the label
    ax.annotate(text, (x1, np.sqrt(y0 * y1)), fontsize=7, xytext=(3, 0),
                textcoords="offset points", zorder=5,
                bbox={"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none", "alpha": 0.85})


def cell_polygons(p: np.ndarray, t: np.ndarray) -> np.ndarray:
    """The cells as polygons (n_cells, corners, 2), triangles and quadrilaterals alike (a
    hanging node is a vertex of its fine cells and lies on the coarse cell's edge)."""
    return np.transpose(p[:2, t], (2, 1, 0))


MESH_PANEL = 4.0  # inches: a final mesh is read at this size, not as a thumbnail


def meshes(artifacts: dict):
    """Final adaptive mesh per formulation (the paper's Figure 1b): each cell coloured by its
    size h_T on one log scale for every panel, so that where the refinement went reads at a
    glance at any mesh size (edges of 10^4 cells would fill the panel)."""
    # one mesh per formulation (and cell): the residual estimator's where it ran (the seed's)
    # at the lowest order, else the first estimator's
    chosen: dict = {}
    for key, data in sorted(artifacts.items(),
                            key=lambda kv: (kv[0][1] != "residual", kv[0][3:], kv[0])):
        if key[2] == "adaptive":
            chosen.setdefault((key[0], *key[4:]), (key, data))
    items = sorted(chosen.values(), key=lambda kv: kv[0])
    if not items:
        return None
    cols = min(4, len(items))
    rows = int(np.ceil(len(items) / cols))
    fig = Figure(figsize=(MESH_PANEL * cols + 1.0, MESH_PANEL * rows))
    axes = fig.subplots(rows, cols, squeeze=False)
    for ax in axes.ravel():
        ax.set_axis_off()
    sizes = [np.log10(vertex_diameters(data["p"][:2], data["t"])) for _, data in items]
    low, high = min(s.min() for s in sizes), max(s.max() for s in sizes)
    art = None
    for ax, (key, data), size in zip(axes.ravel(), items, sizes, strict=False):
        art = PolyCollection(cell_polygons(data["p"], data["t"]), array=size, cmap="viridis",
                             edgecolors="face", linewidths=0.2, antialiased=False)
        art.set_clim(low, high)
        ax.add_collection(art)
        ax.autoscale_view()
        order = f"/P{key[3]}" if len(key) > 3 and key[3] != 1 else ""
        cell = f"/{key[4]}" if len(key) > 4 and key[4] != "tri" else ""
        ax.set_title(f"{key[0]}/{key[1]}{order}{cell}: {int(data['ndofs'])} DOFs", fontsize=9)
        ax.set_aspect("equal")
    fig.colorbar(art, ax=list(axes.ravel()), label="log10 h_T", shrink=0.8)
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
                         cmap="viridis", edgecolors="face", linewidths=0.3, antialiased=False)
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

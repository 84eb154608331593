"""Report figures of 3D scenes (docs/theory.md, section 14.5): the contact pressure on Gamma_C
as a colour map over the contact coordinates, and a slice of the final adaptive meshes through
the plane y = 0, coloured by von Mises stress. Like ``bench.report.figures``, each function
returns a ``matplotlib.figure.Figure`` or None when its data are missing."""

from __future__ import annotations

import numpy as np
from matplotlib.collections import PolyCollection
from matplotlib.figure import Figure
from matplotlib.patches import Circle
from matplotlib.tri import Triangulation

from bench.report.figures import VON_MISES_PERCENTILE

# the tetrahedron's six edges as pairs of its local vertices
TET_EDGES = np.array([[0, 1], [0, 2], [0, 3], [1, 2], [1, 3], [2, 3]])
# the slice plane y = SLICE_OFFSET x (the body's size): just off y = 0, where the scenes' meshes
# have faces, so that the cut meets the elements on one side instead of their common face
SLICE_OFFSET = 1e-9
ZOOM = 1.6  # the pressure maps show the contact zone's disc and this many radii around it


def _adaptive(artifacts: dict) -> list:
    return [(k, v) for k, v in sorted(artifacts.items()) if k[2] == "adaptive"
            and v["p"].shape[0] == 3]


def _grid(count: int, size: float = 4.0):
    cols = min(3, count)
    rows = int(np.ceil(count / cols))
    fig = Figure(figsize=(size * cols + 1, size * rows))
    axes = fig.subplots(rows, cols, squeeze=False)
    for ax in axes.ravel():
        ax.set_axis_off()
    return fig, axes.ravel()


def pressure_maps(artifacts: dict):
    """lambda_h on Gamma_C over the contact coordinates (x, y), per formulation (adaptive, last
    level, first estimator), with the contact zone's disc of the same area (dashed)."""
    chosen = {}
    for key, data in _adaptive(artifacts):
        chosen.setdefault(key[0], (key, data))
    if not chosen:
        return None
    fig, axes = _grid(len(chosen))
    for ax, (formulation, (_, data)) in zip(axes, chosen.items(), strict=False):
        s = data["trace_coordinate"]  # (2, 3, n): the corners' contact coordinates
        n = s.shape[2]
        points = s.transpose(0, 2, 1).reshape(2, -1)  # point 3 f + j: corner j of facet f
        values = np.asarray(data["trace_pressure"]).T.ravel()  # (3, n) -> same order
        shown = Triangulation(points[0], points[1], np.arange(3 * n).reshape(n, 3))
        ax.set_axis_on()
        art = ax.tripcolor(shown, values, shading="gouraud", cmap="magma", vmin=0)
        start, end = data["zone"]
        if np.isfinite(start):  # the disc, and a zoom on it
            centre, radius = 0.5 * (start + end), 0.5 * (end - start)
            ax.add_patch(Circle((centre, 0.0), radius, fill=False, linestyle="--", color="c",
                                linewidth=0.8))
            ax.set_xlim(centre - ZOOM * radius, centre + ZOOM * radius)
            ax.set_ylim(-ZOOM * radius, ZOOM * radius)
        fig.colorbar(art, ax=ax, label="lambda_h")
        ax.set_title(f"{formulation}: {int(data['ndofs'])} DOFs", fontsize=9)
        ax.set_aspect("equal")
    fig.tight_layout()
    return fig


def slice_polygons(p: np.ndarray, t: np.ndarray, y0: float):
    """The polygons (x, z) where the plane y = y0 cuts the tetrahedra (p (3, nv), t (4, nE)):
    (triangles (n3, 3, 2), their elements), (quadrilaterals (n4, 4, 2), their elements)."""
    a, b = t[TET_EDGES[:, 0]], t[TET_EDGES[:, 1]]  # (6, nE)
    ya, yb = p[1, a] - y0, p[1, b] - y0
    crossing = ya * yb < 0
    with np.errstate(invalid="ignore", divide="ignore"):
        frac = np.where(crossing, ya / (ya - yb), np.nan)
    points = p[:, a] + frac[None] * (p[:, b] - p[:, a])  # (3, 6, nE), NaN off the cut
    xz = points[[0, 2]].transpose(2, 1, 0)  # (nE, 6, 2)
    count = crossing.sum(axis=0)
    centre = (np.where(crossing.T[:, :, None], xz, 0.0).sum(axis=1, keepdims=True)
              / np.maximum(count, 1)[:, None, None])
    angle = np.where(crossing.T, np.arctan2(xz[..., 1] - centre[..., 1],
                                            xz[..., 0] - centre[..., 0]), np.inf)
    ordered = np.take_along_axis(xz, np.argsort(angle, axis=1)[:, :, None], axis=1)
    return tuple((ordered[count == k, :k], np.flatnonzero(count == k)) for k in (3, 4))


def mesh_slices(artifacts: dict):
    """Final adaptive meshes cut by the plane y = 0 (x-z view), coloured by von Mises stress
    clipped at its VON_MISES_PERCENTILE-th percentile (the clamped edges are singular)."""
    items = _adaptive(artifacts)
    if not items:
        return None
    fig, axes = _grid(len(items))
    for ax, (key, data) in zip(axes, items, strict=False):
        p, t = data["p"], data["t"]
        y0 = SLICE_OFFSET * np.ptp(p, axis=1).max()
        vm = data["von_mises"]
        top = np.percentile(vm, VON_MISES_PERCENTILE)
        ax.set_axis_on()
        for polygons, elements in slice_polygons(p, t, y0):
            if elements.size:
                collection = PolyCollection(polygons, array=np.minimum(vm[elements], top),
                                            cmap="viridis", edgecolors="k", linewidths=0.1)
                collection.set_clim(0, top)
                ax.add_collection(collection)
        ax.autoscale()
        order = f"/P{key[3]}" if len(key) > 3 and key[3] != 1 else ""
        ax.set_title(f"{key[0]}/{key[1]}{order}: {int(data['ndofs'])} DOFs, slice y = 0",
                     fontsize=9)
        ax.set_aspect("equal")
    fig.tight_layout()
    return fig

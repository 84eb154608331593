"""A triangle mesh from a file (Gmsh ``.msh`` or any format meshio reads) whose physical groups
of lines name boundary parts (docs/scenes.md, "Meshes from Gmsh").

A named group becomes a predicate on points: "on one of the group's segments". Refinement puts
new facet midpoints on the segments of the initial mesh, so the predicate holds on every level.
"""

from __future__ import annotations

import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from skfem import MeshTri

from scenes.base import SceneError


@dataclass(frozen=True, eq=False)
class MeshFile:
    """The body's triangles and the segments (shape (2, 2, m): end point, coordinate, segment)
    of each named boundary group."""

    mesh: MeshTri
    groups: dict[str, np.ndarray]


READ_CELLS = ("triangle", "line", "vertex")  # the body, its boundary groups, named points


def read_mesh_file(path: str | Path, where: str = "mesh") -> MeshFile:
    """Triangles and named line groups of ``path``, read exactly or refused: SceneError (one
    line) when the file does not read, holds no triangles or cells of another type, is not
    flat in the x-y plane, has a degenerate triangle or boundary lines off the body, or its
    line groups carry no names. Clockwise triangles are turned counter-clockwise; nodes of no
    cell at all are left out with a note on standard error."""
    import meshio  # only scenes from files need it

    flag = f"{where}={str(path)!r}"
    try:
        data = meshio.read(path)
    except Exception as error:  # meshio raises many types; the user needs the file and reason
        raise SceneError(f"{flag} does not read as a mesh: {type(error).__name__}: "
                         f"{error}") from None
    _check_cells(data, flag)
    points = np.asarray(data.points, dtype=float)
    if points.shape[1] == 3 and np.any(points[:, 2] != points[0, 2]):
        raise SceneError(f"{flag} is not a 2D mesh: its z coordinates range over "
                         f"[{points[:, 2].min():g}, {points[:, 2].max():g}] (a flat mesh in a "
                         "plane z = const is read)")
    t = np.concatenate([block.data for block in data.cells if block.type == "triangle"])
    used, t = np.unique(t, return_inverse=True)
    others = np.concatenate([np.ravel(b.data) for b in data.cells if b.type != "triangle"]
                            or [np.zeros(0, dtype=int)])
    if np.setdiff1d(others, used).size:
        raise SceneError(f"{flag} has boundary lines or points on nodes of no triangle; "
                         "every named curve must lie on the body's edges")
    if used.size < len(points):
        print(f"note: {flag}: {len(points) - used.size} nodes belong to no cell and are left "
              "out", file=sys.stderr)
    mesh = _counter_clockwise(points[used, :2], t.reshape(-1, 3), flag)
    return MeshFile(mesh, _line_groups(data, path, where))


def _check_cells(data, flag: str) -> None:
    if not any(block.type == "triangle" for block in data.cells):
        raise SceneError(f"{flag} holds no triangles (2D meshes of 3-node triangles are read)")
    other = sorted({block.type for block in data.cells} - set(READ_CELLS))
    if other:
        raise SceneError(f"{flag} holds cells of type {', '.join(other)}; only 3-node "
                         f"triangles are read (with lines and points for the named groups)")


def _counter_clockwise(p: np.ndarray, t: np.ndarray, flag: str) -> MeshTri:
    a, b, c = p[t[:, 0]], p[t[:, 1]], p[t[:, 2]]
    area = (b - a)[:, 0] * (c - a)[:, 1] - (b - a)[:, 1] * (c - a)[:, 0]
    scale = np.ptp(p, axis=0).prod()
    if np.any(np.abs(area) <= 1e-12 * scale):  # relative to the body's bounding box
        raise SceneError(f"{flag} has {int(np.sum(np.abs(area) <= 1e-12 * scale))} degenerate "
                         "triangles (zero area)")
    t = np.where((area < 0)[:, None], t[:, [0, 2, 1]], t)
    return MeshTri(p.T.copy(), t.T.copy())


def _line_groups(data, path, where: str) -> dict[str, np.ndarray]:
    """Segments of each physical group of lines, by the group's name."""
    names = {int(tag): name for name, (tag, dim) in data.field_data.items() if int(dim) == 1}
    tags = data.cell_data.get("gmsh:physical")
    groups: dict[str, list] = {}
    if tags is not None:
        for block, block_tags in zip(data.cells, tags, strict=True):
            if block.type != "line":
                continue
            for tag in np.unique(block_tags):
                if int(tag) in names:
                    ends = data.points[block.data[block_tags == tag], :2]  # (m, 2, 2)
                    groups.setdefault(names[int(tag)], []).append(ends.transpose(1, 2, 0))
    if not groups:
        raise SceneError(f"{where}={str(path)!r} has no named physical groups of lines (name the "
                         "clamped, contact and loaded boundaries with Physical Curve(\"...\"))")
    return {name: np.concatenate(parts, axis=2) for name, parts in groups.items()}


def on_segments(segments: np.ndarray, tolerance: float):
    """A predicate: points (2, ...) within ``tolerance`` of one of ``segments`` (2, 2, m)."""
    a, b = segments[0][:, None, :], segments[1][:, None, :]  # (2, 1, m)
    d = b - a
    length2 = np.maximum((d**2).sum(axis=0), np.finfo(float).tiny)

    def predicate(x: np.ndarray) -> np.ndarray:
        x = np.asarray(x, dtype=float)
        flat = x.reshape(2, -1)
        hit = np.zeros(flat.shape[1], dtype=bool)
        step = max(1, 2_000_000 // segments.shape[2])  # bounded memory: points x segments
        for start in range(0, flat.shape[1], step):
            q = flat[:, start:start + step, None]
            s = np.clip(((q - a) * d).sum(axis=0) / length2, 0.0, 1.0)
            gap = ((q - a - s * d) ** 2).sum(axis=0)
            hit[start:start + step] = (gap <= tolerance**2).any(axis=1)
        return hit.reshape(x.shape[1:])

    return predicate

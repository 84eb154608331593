"""The fields of each combination's last level, or of every level as a series, written through
meshio: the mesh with the displacement, the stress tensor, von Mises stress, the estimator's
element indicators and, where a truth is exact, the element error density; and the contact
boundary with lambda_h and the gap. Read from ``DIR/artifacts/`` (``bench.matrix.artifacts``):
nothing is recomputed."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from bench.export.series import write_pvd, write_xdmf_collection
from bench.matrix.artifacts import load_artifact

FORMATS = {"vtu": ".vtu", "xdmf": ".xdmf"}


def stress_tensor(stress: np.ndarray) -> np.ndarray:
    """(s11, s22, s12) per element as 3 x 3 tensors (plane: zeros in the third row and
    column), the layout ParaView reads as a tensor; in 3D from (s11, s22, s33, s23, s13, s12)."""
    if len(stress) == 6:
        s11, s22, s33, s23, s13, s12 = stress
        return np.stack([s11, s12, s13, s12, s22, s23, s13, s23, s33], axis=1)
    s11, s22, s12 = stress
    out = np.zeros((s11.size, 3, 3))
    out[:, 0, 0], out[:, 1, 1], out[:, 0, 1], out[:, 1, 0] = s11, s22, s12, s12
    return out.reshape(-1, 9)


# meshio's cell type by (dimension, corners of a cell)
MESHIO_CELLS = {(2, 3): "triangle", (2, 4): "quad", (3, 4): "tetra", (3, 8): "hexahedron"}


def body_mesh(data: dict):
    """The cells (in 2D with 3D points, z = 0) with their point and cell fields."""
    import meshio

    planar = data["p"].shape[0] == 2
    points = (np.vstack([data["p"], np.zeros(data["p"].shape[1])]) if planar else data["p"]).T
    u = (np.vstack([data["u"], np.zeros(data["u"].shape[1])]) if planar else data["u"]).T
    cells = {"stress": stress_tensor(data["stress"]), "von_mises": data["von_mises"],
             "indicator": data["indicators"], "error_density": data["error_density"]}
    # a field the run did not compute (no truth: no error density) is left out, not NaN
    cells = {k: v for k, v in cells.items() if np.isfinite(np.asarray(v, dtype=float)).any()}
    kind = MESHIO_CELLS[(data["p"].shape[0], data["t"].shape[0])]
    return meshio.Mesh(points, [(kind, data["t"].T)],
                       point_data={"displacement": u},
                       cell_data={k: [np.asarray(v, dtype=float)] for k, v in cells.items()})


def contact_mesh(data: dict):
    """Gamma_C as line cells (triangles in 3D), each facet with its own points (lambda_h and the
    gap may jump between facets), with lambda_h and the gap at the facet's vertices."""
    import meshio

    vertices = data["trace_vertices"]  # (k, n_facets): the k vertices of each facet
    k, n = vertices.shape
    corners = vertices.ravel()  # point j n + f: vertex j of facet f
    points = data["p"][:, corners]
    if points.shape[0] == 2:
        points = np.vstack([points, np.zeros(k * n)])
    cells = (np.arange(k)[None, :] * n + np.arange(n)[:, None])
    point_data = {"lambda_h": np.asarray(data["trace_pressure"]).ravel(),
                  "gap": np.asarray(data["trace_gap"]).ravel()}
    return meshio.Mesh(points.T, [("line" if k == 2 else "triangle", cells)],
                       point_data=point_data)


LEVELS = ("last", "all")


def export_results(results: str | Path, out: str | Path, fmt: str = "vtu",
                   levels: str = "last") -> list[Path]:
    """Write ``<combination>{ext}`` and ``<combination>-contact{ext}`` per artifact of the
    results folder into ``out`` (``levels="last"``), or with ``levels="all"`` every level into
    ``<combination>/level-NNN{ext}`` plus one series per combination and part
    (``<combination>[-contact].pvd`` for vtu, a temporal ``.xdmf`` collection for xdmf) that
    ParaView opens as one dataset; returns the files written."""
    if fmt not in FORMATS:
        raise ValueError(f"format={fmt!r} is not one of {', '.join(FORMATS)}")
    if levels not in LEVELS:
        raise ValueError(f"levels={levels!r} is not one of {', '.join(LEVELS)}")
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    if levels == "last":
        return [file for path in sorted((Path(results) / "artifacts").glob("*.npz"))
                for file in _write_level(path, out / path.stem, fmt)]
    folders = sorted(p for p in (Path(results) / "artifacts" / "levels").glob("*") if p.is_dir())
    if not folders:
        raise ValueError(f"levels='all': {results} holds no per-level fields (artifacts/levels/ "
                         "is written by runs of this version; rerun, or export levels='last')")
    written = []
    for folder in folders:
        parts = {"": [], "-contact": []}
        for path in sorted(folder.glob("level-*.npz")):
            files = _write_level(path, out / folder.name / path.stem, fmt)
            level = int(path.stem.split("-")[1])
            for suffix, file in zip(parts, files, strict=False):
                parts[suffix].append((level, file))
            written += files
        series = write_pvd if fmt == "vtu" else write_xdmf_collection
        written += [series(out / f"{folder.name}{suffix}.{'pvd' if fmt == 'vtu' else 'xdmf'}",
                           entries) for suffix, entries in parts.items() if entries]
    return written


def _write_level(path: Path, stem: Path, fmt: str) -> list[Path]:
    """The body and the contact boundary of one artifact, as ``stem{ext}`` and
    ``stem-contact{ext}`` ([] for an artifact of a version without fields)."""
    import meshio

    data = load_artifact(path)
    if data is None or "stress" not in data:
        return []
    stem.parent.mkdir(parents=True, exist_ok=True)
    written = []
    for suffix, mesh in (("", body_mesh(data)), ("-contact", contact_mesh(data))):
        target = stem.parent / f"{stem.name}{suffix}{FORMATS[fmt]}"
        meshio.write(target, mesh)
        written.append(target)
    return written

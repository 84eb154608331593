"""The fields of each combination's last level, written through meshio: the mesh with the
displacement, the stress tensor, von Mises stress, the estimator's element indicators and,
where a truth is exact, the element error density; and the contact boundary with lambda_h and
the gap. Read from ``DIR/artifacts/*.npz`` (``bench.matrix.artifacts``): nothing is
recomputed."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from bench.matrix.artifacts import load_artifact

FORMATS = {"vtu": ".vtu", "xdmf": ".xdmf"}


def stress_tensor(stress: np.ndarray) -> np.ndarray:
    """(s11, s22, s12) per element as 3 x 3 tensors (plane: zeros in the third row and
    column), the layout ParaView reads as a tensor."""
    s11, s22, s12 = stress
    out = np.zeros((s11.size, 3, 3))
    out[:, 0, 0], out[:, 1, 1], out[:, 0, 1], out[:, 1, 0] = s11, s22, s12, s12
    return out.reshape(-1, 9)


def body_mesh(data: dict):
    """The triangles with their point and cell fields (3D points, z = 0)."""
    import meshio

    points = np.vstack([data["p"], np.zeros(data["p"].shape[1])]).T
    u = np.vstack([data["u"], np.zeros(data["u"].shape[1])]).T
    cells = {"stress": stress_tensor(data["stress"]), "von_mises": data["von_mises"],
             "indicator": data["indicators"], "error_density": data["error_density"]}
    return meshio.Mesh(points, [("triangle", data["t"].T)], point_data={"displacement": u},
                       cell_data={k: [np.asarray(v, dtype=float)] for k, v in cells.items()})


def contact_mesh(data: dict):
    """Gamma_C as line cells, each facet with its own two points (lambda_h and the gap may
    jump between facets), with lambda_h and the gap at the facet ends."""
    import meshio

    vertices = data["trace_vertices"]  # (2, n_facets): start and end vertex of each facet
    n = vertices.shape[1]
    ends = np.concatenate([vertices[0], vertices[1]])  # point k: start (k < n) or end
    points = np.vstack([data["p"][:, ends], np.zeros(2 * n)]).T
    lines = np.column_stack([np.arange(n), np.arange(n, 2 * n)])
    point_data = {"lambda_h": np.concatenate([data["trace_pressure"][0],
                                              data["trace_pressure"][1]]),
                  "gap": np.concatenate([data["trace_gap"][0], data["trace_gap"][1]])}
    return meshio.Mesh(points, [("line", lines)], point_data=point_data)


def export_results(results: str | Path, out: str | Path, fmt: str = "vtu") -> list[Path]:
    """Write ``<combination>{ext}`` and ``<combination>-contact{ext}`` per artifact of the
    results folder into ``out``; returns the files written."""
    import meshio

    if fmt not in FORMATS:
        raise ValueError(f"format={fmt!r} is not one of {', '.join(FORMATS)}")
    artifacts = sorted((Path(results) / "artifacts").glob("*.npz"))
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    written = []
    for path in artifacts:
        data = load_artifact(path)
        if data is None or "stress" not in data:  # written by a version without fields
            continue
        for suffix, mesh in (("", body_mesh(data)), ("-contact", contact_mesh(data))):
            target = out / f"{path.stem}{suffix}{FORMATS[fmt]}"
            meshio.write(target, mesh)
            written.append(target)
    return written

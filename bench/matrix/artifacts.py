"""Per-combination artifacts of the last level (mesh, displacement, stress, contact pressure),
stored next to the results so that reports can draw meshes and fields without recomputing."""

from __future__ import annotations

import os
import re
from pathlib import Path

import numpy as np

from bench.measure.contact import contact_zone
from bench.sequence.rows import KEYS
from formulations.elasticity import von_mises

PRESSURE_SAMPLES = np.linspace(0.0, 1.0, 9)


def file_stem(*parts) -> str:
    """A file name from names read from a results table: anything but letters, digits, '.',
    '_' and '-' becomes '_', and no part can climb out of its folder ('..', '/')."""
    text = "-".join(str(part) for part in parts if str(part) != "")
    stem = re.sub(r"[^A-Za-z0-9._-]", "_", text).replace("..", "__")
    return stem.lstrip(".") or "_"


def artifact_path(out: str | Path, row) -> Path:
    return Path(out) / "artifacts" / f"{file_stem(*(getattr(row, k) for k in KEYS))}.npz"


def save_artifact(out: str | Path, result) -> Path | None:
    """Write the last level of a sequence (``bench.sequence.loop.LevelResult``); None if it has no
    solution."""
    sol = result.solution
    if sol is None or not np.all(np.isfinite(sol.u)):
        return None
    mesh = sol.elasticity.mesh
    path = artifact_path(out, result.row)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(".tmp.npz")
    np.savez_compressed(
        tmp, p=mesh.p, t=mesh.t, u=sol.elasticity.nodal(sol.u),
        von_mises=von_mises(sol.elasticity.element_stress(sol.u)),
        trace_coordinate=sol.trace.coordinate, pressure=sol.pressure(PRESSURE_SAMPLES),
        zone=np.array(contact_zone(sol)), contact_force=sol.contact_force(),
        ndofs=sol.elasticity.ndofs, level=result.row.level)
    os.replace(tmp, path)
    return path


def load_artifact(path: str | Path) -> dict | None:
    path = Path(path)
    if not path.exists():
        return None
    with np.load(path) as data:
        return {key: data[key] for key in data.files}

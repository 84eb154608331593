"""Per-combination artifacts (mesh, displacement, stress, contact pressure): the last level in
``artifacts/<combination>.npz``, every level in ``artifacts/levels/<combination>/level-NNN.npz``,
stored next to the results so that reports and ``export`` draw meshes and fields without
recomputing."""

from __future__ import annotations

import io
import re
import shutil
import sys
from pathlib import Path

import numpy as np

from bench.matrix.files import atomic_bytes, atomic_path
from bench.measure.contact import contact_zone
from bench.measure.discretisation_error import element_energy_errors
from bench.sequence.rows import name_parts
from formulations.base import FRICTION_STATES
from formulations.elasticity import von_mises

PRESSURE_SAMPLES = 9  # lambda_h's samples per facet (the contact boundary's)


def file_stem(*parts) -> str:
    """A file name from names read from a results table: anything but letters, digits, '.',
    '_' and '-' becomes '_', and no part can climb out of its folder ('..', '/')."""
    text = "-".join(str(part) for part in parts if str(part) != "")
    stem = re.sub(r"[^A-Za-z0-9._-]", "_", text).replace("..", "__")
    return stem.lstrip(".") or "_"


def artifact_path(out: str | Path, row) -> Path:
    return Path(out) / "artifacts" / f"{file_stem(*name_parts(row))}.npz"


def level_artifact_path(out: str | Path, row) -> Path:
    return (Path(out) / "artifacts" / "levels" / file_stem(*name_parts(row))
            / f"level-{row.level:03d}.npz")


def save_artifact(path: Path, result, scene=None) -> Path | None:
    """Write a level of a sequence (``bench.sequence.loop.LevelResult``) to ``path`` (its
    ``level_artifact_path``); None if it has no solution. Fields per element: the centroid
    stress (s11, s22, s12; in 3D s11, s22, s33, s23, s13, s12), von Mises, the estimator's
    squared indicators and, where ``scene`` has an exact solution, the squared energy-norm
    error per element; on Gamma_C: the facets' vertices, lambda_h and the gap at the facet
    ends (the triangles' corners in 3D) (the fields ``python -m bench export`` writes)."""
    sol = result.solution
    if sol is None or not np.all(np.isfinite(sol.u)):
        return None
    mesh = sol.elasticity.mesh
    n_elements = mesh.t.shape[1]
    stress = sol.elasticity.element_stress(sol.u)
    estimate = result.estimate
    indicators = (estimate.indicators if estimate is not None
                  else np.full(n_elements, np.nan))
    trace, dim = sol.trace, mesh.dim()
    ends = sol.pressure(trace.lagrange_points(1))  # (n_facets, 2 or 3): at the facets' vertices
    k = trace.vertices.shape[0]
    gap = (np.asarray(scene.gap(mesh.p[:, trace.vertices].reshape(dim, -1)), dtype=float)
           .reshape(k, -1) if scene is not None else np.full(trace.vertices.shape, np.nan))
    path.parent.mkdir(parents=True, exist_ok=True)
    buffer = io.BytesIO()  # in memory first: a full disk then names the size it needed
    np.savez_compressed(
        buffer, p=mesh.p, t=mesh.t, u=sol.elasticity.nodal(sol.u), stress=stress,
        von_mises=von_mises(stress), indicators=indicators,
        error_density=element_error_density(scene, sol, n_elements),
        trace_vertices=sol.trace.vertices, trace_pressure=ends.T, trace_gap=gap,
        trace_coordinate=sol.trace.coordinate,
        pressure=sol.pressure(trace.samples(PRESSURE_SAMPLES)),
        zone=np.array(contact_zone(sol)), contact_force=sol.contact_force(),
        ndofs=sol.elasticity.ndofs, level=result.row.level, **friction_fields(sol))
    atomic_bytes(buffer.getvalue(), path)
    return path


def friction_fields(sol) -> dict:
    """With friction, per friction point: its contact coordinate, the bound as a stress and the
    state (0 separated, 1 stick, 2 slip: FRICTION_STATES); in 2D also the shear traction and the
    normal and tangential forces on the body (sums of the reactions), in 3D the shear
    traction's length (the tangents differ from point to point)."""
    state = sol.friction
    if state is None:
        return {}
    code = (state.state[:, None] == np.array(FRICTION_STATES)[None, :]).argmax(axis=1)
    if state.coordinate.ndim != 1:
        return dict(friction_coordinate=state.coordinate, friction_state=code,
                    friction_bound=state.bound_traction,
                    friction_shear_size=np.linalg.norm(state.shear.reshape(code.size, -1),
                                                       axis=1))
    return dict(friction_coordinate=state.coordinate, friction_shear=state.shear,
                friction_bound=state.bound_traction, friction_state=code,
                friction_forces=np.array([sol.multipliers.sum(),
                                          -state.tangential_reactions.sum()]))


def publish_last_level(out: str | Path, row) -> Path | None:
    """Copy the level artifact of ``row`` (the sequence's last solved level) to the
    combination's artifact, atomically; None if that level wrote none."""
    source, target = level_artifact_path(out, row), artifact_path(out, row)
    if not source.exists():
        return None
    target.parent.mkdir(parents=True, exist_ok=True)
    with atomic_path(target, source.stat().st_size) as tmp:
        shutil.copyfile(source, tmp)
    return target


def element_error_density(scene, sol, n_elements: int) -> np.ndarray:
    """||u - u_h||^2 per element against the scene's exact solution (NaN without one)."""
    if scene is None or scene.exact is None:
        return np.full(n_elements, np.nan)
    return element_energy_errors(scene, sol)


def load_artifact(path: str | Path) -> dict | None:
    """The fields of an artifact; None if it is missing, or damaged (then named in one line on
    standard error, and left out: nothing is drawn or exported from it)."""
    path = Path(path)
    if not path.exists():
        return None
    try:
        with np.load(path) as data:
            return {key: data[key] for key in data.files}
    except Exception as error:  # a truncated zip, a bad header: numpy raises several types
        print(f"warning: {path} is unreadable ({type(error).__name__}: {error}) and is left "
              "out; delete it, or rerun its sequence to write it again", file=sys.stderr)
        return None

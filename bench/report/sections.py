"""The report's per-scene sections and their figures (PNG files plus base64 for the HTML)."""

from __future__ import annotations

import base64
import io
from pathlib import Path

import numpy as np
import pandas as pd

import bench.report.figures as figures
import bench.report.figures_3d as figures_3d
import bench.report.friction_figures as friction_figures
import bench.report.panels as panels
from bench.matrix.artifacts import artifact_path, file_stem, load_artifact
from bench.matrix.files import atomic_bytes
from bench.sequence.rows import KEYS
from scenes import get_scene

FIGURE_DPI = 100  # the page holds every figure inline: 1400 px wide at most, under 5 MB in all


class Figures:
    """Saves each figure as PNG under ``out/figures`` and keeps its base64 for the HTML."""

    def __init__(self, out: Path):
        self.out = out / "figures"
        self.out.mkdir(parents=True, exist_ok=True)
        self.items: list[dict] = []

    def add(self, figure, name: str, caption: str) -> dict | None:
        if figure is None:
            return None
        buffer = io.BytesIO()
        figure.savefig(buffer, format="png", dpi=FIGURE_DPI)
        data = buffer.getvalue()
        atomic_bytes(data, self.out / f"{name}.png")
        item = {"file": f"figures/{name}.png", "caption": caption,
                "data": base64.b64encode(data).decode("ascii")}
        self.items.append(item)
        return item


def _artifacts(results: Path | None, group: pd.DataFrame) -> dict:
    out = {}
    if results is None:
        return out
    for _, row in group.drop_duplicates(KEYS).iterrows():
        data = load_artifact(artifact_path(results, row))
        if data is not None:
            out[(row["formulation"], row["estimator"], row["strategy"],
                 int(row.get("order", 1)), str(row.get("cell", "tri")))] = data
    return out


def _scene(name: str):
    try:
        return get_scene(name)
    except KeyError:
        return None


def _pressure_curve(scene, artifacts: dict):
    """The true pressure to draw beside lambda_h: the exact one, or the scene's closed-form
    prediction at the computed contact force of the first adaptive artifact."""
    if scene is None:
        return None
    if scene.exact is not None:
        s = np.linspace(*np.sort(scene.contact_coordinate(scene.mesh.p))[[0, -1]], 801)
        return s, scene.exact.pressure(s), "exact pressure"
    data = _first_adaptive(artifacts)
    if scene.predict_contact is None or data is None:
        return None
    predicted = scene.predict_contact(float(data["contact_force"]))
    b = predicted.half_width
    s = np.linspace(predicted.centre - 1.5 * b, predicted.centre + 1.5 * b, 601)
    return s, predicted.pressure(s), predicted.label


def _shear_curve(scene, artifacts: dict):
    """The true shear traction: the exact one, or the scene's partial-slip prediction at the
    forces of the first adaptive artifact with friction."""
    if scene is None:
        return None
    if scene.exact is not None and scene.exact.shear is not None:
        s = np.linspace(*np.sort(scene.contact_coordinate(scene.mesh.p))[[0, -1]], 801)
        return s, scene.exact.shear(s), "exact shear traction"
    data = next(iter(v for k, v in sorted(artifacts.items())
                     if k[2] == "adaptive" and "friction_forces" in v), None)
    if scene.predict_stick is None or data is None:
        return None
    predicted = scene.predict_stick(*map(float, data["friction_forces"]))
    b = predicted.half_width
    s = np.linspace(predicted.centre - 1.5 * b, predicted.centre + 1.5 * b, 601)
    return s, predicted.shear(s), predicted.label


def _first_adaptive(artifacts: dict):
    return next(iter(v for k, v in sorted(artifacts.items()) if k[2] == "adaptive"), None)


def field_figures(scene, name: str, artifacts: dict, preferred) -> tuple:
    """The 2D figures drawn from the artifacts: meshes, deformed body, pressure curve."""
    return (
        (figures.meshes(artifacts), "meshes",
         "Final adaptive meshes per formulation, refined by the residual estimator where it "
         "ran at the lowest order run, each cell coloured by its size h_T (the paper's "
         "Figure 1b)."),
        (figures.deformed(preferred, name), "deformed",
         "Deformed body coloured by von Mises stress; the colour scale is clipped at the "
         f"{figures.VON_MISES_PERCENTILE:g}th percentile so that a few peaks (where the "
         "stress concentrates, e.g. at the paper scene's clamped corners) do not hide the "
         "field (the paper's Figure 1a)."),
        (figures.pressures(artifacts, _pressure_curve(scene, artifacts)), "pressure",
         "Contact pressure lambda_h along Gamma_C (adaptive, last level) per formulation; "
         "dotted lines are the contact-zone end points. The penalty's pressure "
         "(u_hn - g_h)_+ / eps is a pointwise formula: its spikes at the peak and at the "
         "zone's ends are the formulation's, not noise (Known limitations)."),
        (friction_figures.shear_traction(artifacts, _shear_curve(scene, artifacts)), "shear",
         "Shear traction sigma_t,h along Gamma_C (adaptive, last level) per formulation, "
         "dotted: the friction bound; below, where each friction point sticks, slips or is "
         "separated."))


def _stick_circles(scene):
    """The exact stick and contact zones' radii of a 3D scene with friction, or None."""
    exact = None if scene is None else scene.exact
    if exact is None or exact.stick_zone is None:
        return None
    return exact.stick_zone[1], exact.contact_zone[1]


def field_figures_3d(scene, name: str, artifacts: dict, preferred) -> tuple:
    """The 3D figures drawn from the artifacts: pressure maps, mesh slices and, with friction,
    the friction states over Gamma_C."""
    return (
        (figures_3d.pressure_maps(artifacts), "pressure",
         "Contact pressure lambda_h on Gamma_C over the contact coordinates (x, y) (adaptive, "
         "last level) per formulation; the dashed circle has the contact zone's area."),
        (figures_3d.mesh_slices(artifacts), "meshes",
         "Final adaptive meshes cut by the plane y = 0, coloured by von Mises stress (clipped "
         f"at its {figures.VON_MISES_PERCENTILE:g}th percentile)."),
        (friction_figures.state_maps(artifacts, _stick_circles(scene)), "friction",
         "Where each friction point sticks, slips or is separated over Gamma_C (adaptive, last "
         "level) per formulation, larger where |sigma_t,h| is nearer its bound; dashed: the "
         "exact stick and contact zones."))


FIELD_FIGURES = {2: field_figures, 3: field_figures_3d}  # by the scene's dimension
SCENE_PICTURES = {2: figures.scene_picture}  # a 3D scene has none


def scene_section(name: str, group: pd.DataFrame, results: Path | None, figs: Figures,
                  truth: dict) -> dict:
    scene = _scene(name)
    artifacts = _artifacts(results, group)
    section = {"name": name, "truth": truth.get(name, {"kind": "unknown"}), "figures": []}
    preferred = _first_adaptive(artifacts)
    # the figures of the scene's dimension (an unregistered scene's: 2D, without a picture)
    dim = scene.dim if scene is not None else 2
    fields, picture = FIELD_FIGURES[dim], SCENE_PICTURES.get(dim)
    for figure, suffix, caption in (
            (picture(scene) if picture and scene is not None else None, "scene",
             "Geometry (initial mesh), boundary parts and the obstacle."),
            (panels.convergence(group), "convergence",
             "One panel per formulation: the error (solid) and eta (dashed) against ndofs, "
             "colour = estimator, marker = strategy, with O(h^1/2) and O(h) slope triangles "
             "(the paper's Figure 2)."),
            (panels.effectivity(group), "effectivity",
             "Effectivity index eta / ||u - u_h|| per formulation, colour = estimator, marker = "
             "strategy; crosses mark rows whose reference is too coarse."),
            (panels.work_precision(group), "work-precision",
             "Work-precision: the error (eta without a truth) against the cumulative wall time "
             "of each sequence (as the matrix timed it), one panel per polynomial order, "
             "colour = formulation, marker = strategy, one line per estimator."),
            *fields(scene, name, artifacts, preferred)):
        item = figs.add(figure, file_stem(name, suffix), caption)
        if item is not None:
            section["figures"].append(item)
    if scene is None:
        section["missing"] = f"scene {name!r} is not registered here: no picture"
    return section

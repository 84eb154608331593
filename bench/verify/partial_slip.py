"""Computed partial slip against a scene's prediction (``Scene.predict_stick``: the coupled
half-plane's stick zone and shear traction in 2D, Mindlin's under Hertz's pressure in 3D) at
the computed normal and tangential forces (docs/theory.md, 17.6 and 19.4)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from bench.matrix.config import RunConfig
from bench.matrix.config_files import run_fields
from bench.matrix.spec import build_scene
from bench.matrix.task import why_skipped
from bench.sequence.loop import run_sequence
from formulations.friction.state import traction_size
from scenes.half_plane import zone_end

PEAK_SAMPLES = 20001  # points over +-b where the predicted peak shear is sought
FACET_SAMPLES = 9  # where sigma_t,h is sampled on each facet (the contact boundary's samples)
FORCE_POINTS = 4  # Gauss points per facet for P and Q (exact for cubic tractions)


def partial_slip_table(run: dict) -> pd.DataFrame:
    """One row per sequence of ``run`` (the ``[partial_slip]`` entry of expected.toml, a run
    file's keys) that can run: computed and predicted stick-zone half-width and peak shear
    traction at the last level, their relative errors, and where the stick zone's centre is."""
    rows = []
    for spec in RunConfig(**run_fields(run, "[partial_slip]")).specs():
        scene = build_scene(spec)
        if why_skipped(scene, spec.formulation, spec.solver, spec.estimator,
                       dict(spec.formulation_options), spec.order, spec.cell,
                       spec.strategy) is not None:  # e.g. a formulation without friction
            continue
        *_, result = run_sequence(scene, spec.formulation, spec.solver, spec.estimator,
                                  spec.loop)
        rows.append({"scene": scene.name, **spec.labels, "formulation": spec.formulation,
                     "order": spec.order, "ndofs": result.row.ndofs,
                     "status": result.row.status, **compare(scene, result.solution)})
    table = pd.DataFrame(rows)
    if len(table):
        table["stick_half_width_error"] = (table["stick_half_width"]
                                           / table["predicted_stick_half_width"] - 1)
        table["peak_shear_error"] = table["peak_shear"] / table["predicted_peak_shear"] - 1
        table["stick_centre_error"] = ((table["stick_centre"] - table["predicted_stick_centre"])
                                       / table["half_width"])
        table["cattaneo_mindlin_error"] = (table["stick_half_width"]
                                           / table["cattaneo_mindlin_stick_half_width"] - 1)
    return table


def stick_ends(state) -> tuple[float, float]:
    """The stick zone's ends along a 2D Gamma_C between the friction points: where
    (mu p - |q|)^2, linear near an end (the margin vanishes like a square root), extrapolates
    to zero from the two outermost stick points (``scenes.half_plane.zone_end``); the extreme
    stick points themselves on a 3D surface."""
    if np.ndim(state.coordinate) != 1:
        return state.zone("stick")
    order = np.argsort(state.coordinate)
    x = np.asarray(state.coordinate)[order]
    margin = (state.bound_traction - np.abs(state.shear))[order]
    stick = (state.state == "stick")[order]
    return tuple(zone_end(x, stick, np.maximum(margin, 0.0), side) for side in (-1, 1))


def compare(scene, solution) -> dict:
    """The forces, the stick zone and the peak shear of ``solution`` beside the prediction: P
    the normal and Q the tangential force on the body (the integrals of lambda_h and
    sigma_t,h), the stick zone between the friction points (``stick_ends``; from the extreme
    stick points: ``stick_half_width_nodes``), the peak of |sigma_t,h| on every contact
    facet."""
    state = solution.friction
    trace = solution.trace
    t, w = trace.rule(2 * FORCE_POINTS - 1)
    normal_force = solution.contact_force(FORCE_POINTS)
    traction = state.traction(t)  # in 3D a vector: Q is its x component (the slide's)
    tangential_force = float(trace.integrate(trace.slide_component(traction), w).sum())
    peak = traction_size(state.traction(trace.samples(FACET_SAMPLES)))
    predicted = scene.predict_stick(normal_force, tangential_force)
    start, end = stick_ends(state)
    nodes = state.zone("stick")
    b = predicted.half_width
    hertz_b = scene.predict_contact(normal_force).half_width
    samples = np.linspace(predicted.centre - b, predicted.centre + b, PEAK_SAMPLES)
    return {"contact_force": normal_force, "tangential_force": tangential_force,
            "stick_half_width": 0.5 * (end - start), "stick_centre": 0.5 * (end + start),
            "stick_half_width_nodes": 0.5 * (nodes[1] - nodes[0]),
            "predicted_stick_half_width": predicted.stick_half_width, "half_width": b,
            "predicted_stick_centre": predicted.centre,
            "cattaneo_mindlin_stick_half_width": hertz_b * np.sqrt(max(
                1 - abs(tangential_force) / (predicted.coefficient * normal_force), 0.0)),
            "peak_shear": float(peak.max()),
            "predicted_peak_shear": float(np.abs(predicted.shear(samples)).max())}

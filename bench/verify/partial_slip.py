"""Computed partial slip against a scene's closed form (``Scene.predict_stick``: Cattaneo and
Mindlin's stick zone and shear traction under Hertz's pressure) at the computed normal and
tangential forces (docs/theory.md, 17.6)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from bench.matrix.config import RunConfig
from bench.matrix.config_files import run_fields
from bench.matrix.spec import build_scene
from bench.matrix.task import why_skipped
from bench.sequence.loop import run_sequence
from formulations.friction.state import traction_size

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
    return table


def compare(scene, solution) -> dict:
    """The forces, the stick zone and the peak shear of ``solution`` beside the prediction: P
    the normal and Q the tangential force on the body (the integrals of lambda_h and
    sigma_t,h), the stick zone from the friction points' states, the peak of |sigma_t,h| on
    every contact facet."""
    state = solution.friction
    trace = solution.trace
    t, w = trace.rule(2 * FORCE_POINTS - 1)
    normal_force = solution.contact_force(FORCE_POINTS)
    traction = state.traction(t)  # in 3D a vector: Q is its x component (the slide's)
    tangential_force = float(trace.integrate(trace.slide_component(traction), w).sum())
    peak = traction_size(state.traction(trace.samples(FACET_SAMPLES)))
    predicted = scene.predict_stick(normal_force, tangential_force)
    start, end = state.zone("stick")
    b = predicted.half_width
    samples = np.linspace(predicted.centre - b, predicted.centre + b, PEAK_SAMPLES)
    return {"contact_force": normal_force, "tangential_force": tangential_force,
            "stick_half_width": 0.5 * (end - start), "stick_centre": 0.5 * (end + start),
            "predicted_stick_half_width": predicted.stick_half_width, "half_width": b,
            "peak_shear": float(peak.max()),
            "predicted_peak_shear": float(np.abs(predicted.shear(samples)).max())}

"""Computed contact against a scene's closed-form prediction (``Scene.predict_contact``, e.g.
Hertz's half-width and peak pressure) at the computed contact force."""

from __future__ import annotations

import pandas as pd

from bench.matrix.config import RunConfig
from bench.matrix.config_files import run_fields
from bench.matrix.spec import build_scene
from bench.measure.contact import contact_zone
from bench.measure.zone_edge import square_root_zone
from bench.sequence.loop import run_sequence


def closed_form_table(runs: list[dict]) -> pd.DataFrame:
    """One row per sequence of ``runs`` (the ``[[closed_form]]`` entries of expected.toml, a
    run file's keys each: one per scene, formulation and order): computed and predicted
    half-width (the contact radius in 3D, that of the disc of the contact zone's area), the same
    with the zone's edge placed by the square-root law (``edge_half_width``,
    ``bench.measure.zone_edge``) and peak pressure, and their relative errors, at the last
    level."""
    rows = []
    for k, run in enumerate(runs):
        for spec in RunConfig(**run_fields(run, f"[[closed_form]] {k + 1}")).specs():
            scene = build_scene(spec)
            *_, result = run_sequence(scene, spec.formulation, spec.solver, spec.estimator,
                                      spec.loop)
            rows.append(_compare(scene, spec, result))
    table = pd.DataFrame(rows)
    table["half_width_error"] = table["half_width"] / table["predicted_half_width"] - 1
    table["edge_half_width_error"] = (table["edge_half_width"] / table["predicted_half_width"]
                                      - 1)
    table["peak_pressure_error"] = (table["peak_pressure"] / table["predicted_peak_pressure"]
                                    - 1)
    return table


def _compare(scene, spec, result) -> dict:
    """The computed contact of ``result``'s last level against the scene's prediction."""
    sol = result.solution
    force = sol.contact_force()
    predicted = scene.predict_contact(force)
    start, end = contact_zone(sol)
    edge_start, edge_end = square_root_zone(sol)
    b = predicted.half_width
    s = sol.trace.around(predicted.centre, b)  # where the computed peak pressure is sought
    return {"scene": scene.name, "formulation": spec.formulation, "order": spec.order,
            "dim": scene.dim, "ndofs": result.row.ndofs, "contact_force": force,
            "half_width": 0.5 * (end - start), "predicted_half_width": b,
            "edge_half_width": 0.5 * (edge_end - edge_start),
            "peak_pressure": float(sol.pressure_at(s).max()),
            "predicted_peak_pressure": predicted.peak_pressure}

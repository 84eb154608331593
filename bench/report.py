"""The comparison report: ``reports/README.md`` and ONE self-contained ``reports/index.html``,
rendered by Jinja2 templates (``bench/templates``) from the same data, a pure function of a
results folder (results.parquet, plus artifacts/, truth.json and run.json when present)."""

from __future__ import annotations

import base64
import io
import json
from pathlib import Path

import jinja2
import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

from bench import figures
from bench.artifacts import artifact_path, load_artifact
from bench.hard_verdicts import LOSS_TOLERANCE, PRESSURE_TOLERANCE, hard_display
from bench.rates import RATE_LEVELS, rates_table
from bench.report_tables import (
    accuracy_table,
    agreement_table,
    effectivity_table,
    failure_table,
    rate_verdicts,
    timing_table,
)
from bench.rows import COLUMNS, KEYS

TEMPLATES = Path(__file__).with_name("templates")


def latest_run(table: pd.DataFrame) -> pd.DataFrame:
    """Keep, per combination, the rows of the most recent run that produced it."""
    last = table.groupby(KEYS)["run_id"].transform("max")
    return table[table["run_id"] == last]


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
        figure.savefig(buffer, format="png", dpi=110)
        plt.close(figure)
        data = buffer.getvalue()
        (self.out / f"{name}.png").write_bytes(data)
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
            out[(row["formulation"], row["estimator"], row["strategy"])] = data
    return out


def _scene(name: str):
    from scenes import get_scene

    try:
        return get_scene(name)
    except KeyError:
        return None


def _pressure_curve(scene, artifacts: dict):
    if scene is None:
        return None
    if scene.exact is not None:
        s = np.linspace(*np.sort(scene.contact_coordinate(scene.mesh.p))[[0, -1]], 801)
        return s, scene.exact.pressure(s), "exact pressure"
    if scene.name == "hertz" and artifacts:
        from scenes.hertz import hertz_prediction

        data = next(iter(v for k, v in sorted(artifacts.items()) if k[2] == "adaptive"), None)
        if data is None:
            return None
        hertz = hertz_prediction(scene, float(data["contact_force"]))
        s = np.linspace(-1.5 * hertz["half_width"], 1.5 * hertz["half_width"], 601)
        values = hertz["peak_pressure"] * np.sqrt(np.clip(1 - (s / hertz["half_width"])**2, 0,
                                                          None))
        return s, values, f"Hertz, b = {hertz['half_width']:.4g}, p0 = {hertz['peak_pressure']:.4g}"
    return None


def scene_section(name: str, group: pd.DataFrame, results: Path | None, figs: Figures,
                  truth: dict) -> dict:
    scene = _scene(name)
    artifacts = _artifacts(results, group)
    section = {"name": name, "truth": truth.get(name, {"kind": "unknown"}), "figures": []}
    preferred = artifacts.get(("mixed", "residual", "adaptive")) or next(
        iter(v for k, v in sorted(artifacts.items()) if k[2] == "adaptive"), None)
    for figure, suffix, caption in (
            (figures.scene_picture(scene) if scene is not None else None, "scene",
             "Geometry (initial mesh), boundary parts and the obstacle."),
            (figures.convergence(group), "convergence",
             "Error and estimator against ndofs, uniform (squares) and adaptive (circles), with "
             "O(h^1/2) and O(h) slope triangles (the paper's Figure 2)."),
            (figures.effectivity(group), "effectivity",
             "Effectivity index eta / ||u - u_h||; crosses mark rows whose reference is too "
             "coarse."),
            (figures.work_precision(group), "work-precision",
             "Work-precision: error (eta without a truth) against cumulative wall time and "
             "against the level's solve time."),
            (figures.meshes(artifacts), "meshes",
             "Final adaptive meshes per formulation/estimator (the paper's Figure 1b)."),
            (figures.deformed(preferred, name), "deformed",
             "Deformed body coloured by von Mises stress; the colour scale is clipped at the "
             f"{figures.VON_MISES_PERCENTILE:g}th percentile because the stress is singular at "
             "the clamped corners (the paper's Figure 1a)."),
            (figures.pressures(artifacts, _pressure_curve(scene, artifacts)), "pressure",
             "Contact pressure lambda_h along Gamma_C (adaptive, last level) per formulation; "
             "dotted lines are the contact-zone end points.")):
        item = figs.add(figure, f"{name}-{suffix}", caption)
        if item is not None:
            section["figures"].append(item)
    if scene is None:
        section["missing"] = f"scene {name!r} is not registered here: no picture"
    return section


def write_report(table: pd.DataFrame, out: str | Path, results: str | Path | None = None,
                 command: str = "") -> Path:
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    results = Path(results) if results is not None else None
    missing = [c for c in COLUMNS if c not in table.columns]
    table = table.reindex(columns=list(dict.fromkeys([*COLUMNS, *table.columns])))
    everything = latest_run(table) if len(table) else table
    rows = everything[everything["level"] >= 0]
    run_info = {}
    if results is not None and (results / "run.json").exists():
        run_info = json.loads((results / "run.json").read_text())
    truth = {}
    if results is not None and (results / "truth.json").exists():
        truth = json.loads((results / "truth.json").read_text())
    hard, hard_figures = None, []
    figs = Figures(out)
    if results is not None and (results / "hard.csv").exists():
        raw = pd.read_csv(results / "hard.csv")
        hard = hard_display(raw)
        item = figs.add(figures.hard_stability(raw, PRESSURE_TOLERANCE), "hard-stability",
                        "Hard cases: the mixed method's inf-sup constant beta_h against ndofs "
                        "for h/H = 1, 1/2, 1/4 (bounded below only for h/H <= 1/2); the "
                        "penalty's penetration and condition estimate against eps_0; and each "
                        "solver's pressure loss against eps_0, with the bar for 'accurate'.")
        hard_figures = [item] if item is not None else []
    scenes = [scene_section(name, group, results, figs, truth)
              for name, group in rows.groupby("scene", sort=True)]
    rates = rates_table(rows) if len(rows) else pd.DataFrame()
    head = everything.iloc[0] if len(everything) else pd.Series(dtype=object)
    context = {
        "command": command or run_info.get("command", "(not recorded)"),
        "configuration": run_info.get("configuration", {}),
        "commit": head.get("commit", ""), "versions": head.get("versions", ""),
        "machine": head.get("machine", ""), "python": head.get("python", ""),
        "rate_levels": RATE_LEVELS, "loss_tolerance": LOSS_TOLERANCE,
        "pressure_tolerance": PRESSURE_TOLERANCE, "missing_columns": missing, "scenes": scenes,
        "tables": {
            "rates": rate_verdicts(rates), "effectivity": effectivity_table(rates),
            "accuracy": accuracy_table(rows), "timing": timing_table(rows),
            "agreement": agreement_table(rows), "failures": failure_table(everything),
            "hard": hard if hard is not None else pd.DataFrame()},
        "hard_run": hard is not None, "hard_figures": hard_figures,
        "n_rows": len(everything), "n_too_coarse": int(rows["reference_too_coarse"]
                                                        .fillna(False).astype(bool).sum()),
    }
    env = jinja2.Environment(loader=jinja2.FileSystemLoader(TEMPLATES),
                             autoescape=jinja2.select_autoescape(["html", "html.j2"]),
                             undefined=jinja2.StrictUndefined, trim_blocks=True,
                             lstrip_blocks=True)
    env.filters["markdown_table"] = lambda t: t.to_markdown(index=False) if len(t) else "None."
    env.filters["records"] = lambda t: t.to_dict("records")
    (out / "index.html").write_text(env.get_template("report.html.j2").render(**context))
    path = out / "README.md"
    path.write_text(env.get_template("report.md.j2").render(**context))
    return path

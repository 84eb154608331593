"""The comparison report: ``README.md`` and one self-contained ``index.html``, rendered by
Jinja2 templates (``bench/report/templates``) from the same data, a pure function of a results
folder (results.parquet, plus artifacts/, truth.json, run.json and hard.csv when present)."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import jinja2
import pandas as pd

from bench.hard import LOSS_TOLERANCE, PRESSURE_TOLERANCE, check_expected, hard_display
from bench.hard.matrix import matrix_html, matrix_markdown, verdict_matrix
from bench.hard.registry import CASE_FIGURES
from bench.matrix.artifacts import file_stem
from bench.matrix.files import atomic_text
from bench.matrix.rates import RATE_LEVELS, judged_levels, rates_table
from bench.matrix.scene_files import load_scene_files
from bench.report.estimator_figures import ESTIMATOR_CAPTION, estimator_effectivity
from bench.report.goal_figures import goal_section
from bench.report.orders import order_section
from bench.report.questions import questions
from bench.report.sections import Figures, scene_section
from bench.report.stopping_figures import STOPPING_CAPTION, components_figure, work_saved
from bench.report.summary import first_screen
from bench.report.tables import (
    accuracy_table,
    agreement_table,
    effectivity_table,
    estimator_summary,
    failure_table,
    rate_counts,
    rate_verdicts,
    timing_table,
)
from bench.report.verdict import EFFECTIVITY_FROM_DOFS
from bench.sequence.rows import COLUMNS, INTERRUPTED, KEYS, with_labels
from bench.verify import load_expected

TEMPLATES = Path(__file__).with_name("templates")


def cut_short(table: pd.DataFrame) -> pd.Series:
    """Per row: its sequence did not finish (interrupted, or running or killed: a keyed
    sequence without an end). Rows of older tables carry no key and count as finished."""
    end, key = table["sequence_end"], table["sequence_key"]
    return (end == INTERRUPTED) | ((end == "") & (key != ""))


def latest_run(table: pd.DataFrame) -> pd.DataFrame:
    """Keep, per combination, the rows of its most recent finished run; a cut-short run only
    where no finished run of that combination exists."""
    table = with_labels(table)
    rank = (~cut_short(table)).astype(int).astype(str) + "|" + table["run_id"].astype(str)
    best = rank.groupby([table[k] for k in KEYS]).transform("max")
    return table[rank == best]


def read_json(results: Path | None, name: str) -> dict:
    """A JSON file of the results folder (run.json, truth.json); {} where it is absent."""
    if results is None or not (results / name).exists():
        return {}
    return json.loads((results / name).read_text())


def _hard_section(results: Path | None, figs: Figures) -> tuple[pd.DataFrame | None, list,
                                                                  dict | None]:
    """The hard cases' full table, figures and verdict matrix (HTML and Markdown), if the
    results folder has hard.csv."""
    if results is None or not (results / "hard.csv").exists():
        return None, [], None
    raw = pd.read_csv(results / "hard.csv")
    items = [figs.add(figure.draw(raw[raw["case"] == case]), file_stem("hard", case),
                      figure.caption)
             for case, figure in CASE_FIGURES.items() if (raw["case"] == case).any()]
    matrix = verdict_matrix(raw)
    return (hard_display(raw), [item for item in items if item is not None],
            {"html": matrix_html(matrix), "markdown": matrix_markdown(matrix),
             "csv": str(results / "hard.csv"), "rows": len(raw)})


def _tables(everything: pd.DataFrame, rows: pd.DataFrame, hard) -> dict:
    rates = rates_table(rows) if len(rows) else pd.DataFrame()
    return {"rates": rate_verdicts(rates), "effectivity": effectivity_table(rates),
            "estimators": estimator_summary(rows) if len(rows) else pd.DataFrame(),
            "accuracy": accuracy_table(rows), "timing": timing_table(rows),
            "agreement": agreement_table(rows), "failures": failure_table(everything),
            "hard": hard if hard is not None else pd.DataFrame()}


def _render(context: dict, out: Path) -> Path:
    env = jinja2.Environment(loader=jinja2.FileSystemLoader(TEMPLATES),
                             autoescape=jinja2.select_autoescape(["html", "html.j2"]),
                             undefined=jinja2.StrictUndefined, trim_blocks=True,
                             lstrip_blocks=True)
    env.filters["markdown_table"] = lambda t: t.to_markdown(index=False) if len(t) else "None."
    env.filters["records"] = lambda t: t.to_dict("records")
    atomic_text(env.get_template("report.html.j2").render(**context), out / "index.html")
    path = out / "README.md"
    atomic_text(env.get_template("report.md.j2").render(**context), path)
    return path


def write_report(table: pd.DataFrame, out: str | Path, results: str | Path | None = None,
                 command: str = "") -> Path:
    """Render ``out/README.md``, ``out/index.html`` and ``out/figures/*.png`` from a result
    table (and its results folder); returns the README's path."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    results = Path(results) if results is not None else None
    missing = [c for c in COLUMNS if c not in table.columns]
    table = table.reindex(columns=list(dict.fromkeys([*COLUMNS, *table.columns])))
    everything = latest_run(table) if len(table) else table
    rows = everything[everything["level"] >= 0]
    run_info, truth = read_json(results, "run.json"), read_json(results, "truth.json")
    _load_scene_files(run_info)
    figs = Figures(out)
    hard, hard_figures, hard_matrix = _hard_section(results, figs)
    head = everything.iloc[0] if len(everything) else pd.Series(dtype=object)
    tables = _tables(everything, rows, hard)
    orders = order_section(rows, figs)
    return _render({
        "command": command or run_info.get("command", "(not recorded)"),
        "configuration": run_info.get("configuration", {}),
        "commit": head.get("commit", ""), "versions": head.get("versions", ""),
        "machine": head.get("machine", ""), "python": head.get("python", ""),
        "rate_levels": RATE_LEVELS, "loss_tolerance": LOSS_TOLERANCE,
        "pressure_tolerance": PRESSURE_TOLERANCE, "missing_columns": missing,
        "scenes": [scene_section(name, group, results, figs, truth)
                   for name, group in rows.groupby("scene", sort=True)],
        "tables": tables, "rate_counts": rate_counts(tables["rates"]),
        "summary": first_screen(everything, rows, tables["rates"], truth, results),
        "effectivity_from": EFFECTIVITY_FROM_DOFS,
        "questions": questions(tables, hard_verdicts(results), orders),
        "hard_verdicts": hard_verdicts(results),
        "numerics": run_info.get("numerics", {}),
        "estimator_figure": figs.add(estimator_effectivity(judged_levels(rows))
                                     if len(rows) else None, "estimators", ESTIMATOR_CAPTION),
        "orders": orders,
        "stopping_figure": figs.add(components_figure(rows) if len(rows) else None,
                                    "stopping", STOPPING_CAPTION),
        "stopping_table": work_saved(rows) if len(rows) else pd.DataFrame(),
        "goals": goal_section(rows, figs),
        "hard_run": hard is not None, "hard_figures": hard_figures, "hard_matrix": hard_matrix,
        "n_rows": len(everything), "n_too_coarse": int(rows["reference_too_coarse"]
                                                        .fillna(False).astype(bool).sum()),
        **_provenance_of_rows(everything, run_info),
    }, out)


def hard_verdicts(results: Path | None) -> str:
    """'k of n hard verdicts as expected' and the unexpected ones ('' when not run)."""
    if results is None or not (results / "hard.csv").exists():
        return ""
    checks = check_expected(pd.read_csv(results / "hard.csv"), load_expected().get("hard", []))
    wrong = [f"{c['case']}/{c['formulation']}/{c['solver']}/{c['variant']}: {c['verdict']}, "
             f"expected {c['expected']}" for c in checks if not c["passed"]]
    return (f"{len(checks) - len(wrong)} of {len(checks)} hard verdicts as expected"
            + (f"; unexpected: {'; '.join(wrong)}" if wrong else ""))


def _load_scene_files(run_info: dict) -> None:
    """The run's scene files, so that its scenes get their pictures; a file that is gone or no
    longer loads only costs the picture (the section says so)."""
    runs = [run_info, *run_info.get("earlier", [])]
    files = dict.fromkeys(f for run in runs for f in run.get("configuration", {})
                          .get("scene_files", []))
    for file in files:
        try:
            load_scene_files([file])
        except ValueError as error:
            print(f"note: {error}; its scenes are drawn without a picture", file=sys.stderr)


def _provenance_of_rows(everything: pd.DataFrame, run_info: dict) -> dict:
    """Which rows an earlier run computed (reused), and which sequences were cut short."""
    current = run_info.get("run_id")
    reused = everything[everything["run_id"] != current] if current else everything.iloc[:0]
    short = everything[cut_short(everything)] if len(everything) else everything
    return {"n_reused": len(reused), "reused_runs": ", ".join(sorted(set(reused["run_id"]))),
            "cut_short": ", ".join(sorted({"/".join(str(r[k]) for k in KEYS[:5])
                                           for _, r in short.iterrows()}))}

"""The rate study's report: ``README.md`` with its tables and ``figures/*.png`` (convergence
against the predictions, local slopes, effectivity on every level)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from bench.report.figures import colour, line_style
from bench.sequence.rows import KEYS, phase_time, with_labels
from bench.study.analysis import (
    EFFECTIVITY_FROM,
    NEARLY,
    SHOWN,
    asymptotic_table,
    local_slopes,
    nearly_half_range,
    predictions,
)
from bench.study.seed_figures import write_seed_figures
from bench.verify.gates import check_gates, verdict_table
from formulations import STATUS_OK

MARKERS = {"uniform": "s", "adaptive": "o"}


# a sequence of one scene in the figures
SEQUENCE = ["formulation", "formulation_options", "estimator", "strategy", "order"]


def _sequences(table: pd.DataFrame, scene: str):
    ok = with_labels(table[(table["scene"] == scene) & (table["status"] == STATUS_OK)])
    for key, group in ok.groupby(SEQUENCE, sort=True):
        yield key, group.sort_values("ndofs")


def _draw(axes, key, x, y) -> None:
    """One sequence's line: colour by formulation, style by estimator, marker by strategy."""
    formulation, options, estimator, strategy, order = key
    name = f"{formulation}:{options}" if options else formulation
    axes.plot(x, y, color=colour(formulation), linestyle=line_style(estimator),
              marker=MARKERS.get(strategy, "x"), markersize=3,
              label=f"{name}/{estimator}/{strategy}/p{order}")


def _finish(axes, xlabel: str, ylabel: str, title: str) -> None:
    axes.set_xlabel(xlabel)
    axes.set_ylabel(ylabel)
    axes.set_title(title)
    axes.legend(fontsize=5, ncol=2)
    axes.grid(True, which="both", alpha=0.3)


def convergence_figure(table: pd.DataFrame, scene: str, column: str, label: str,
                       predicted: pd.DataFrame) -> Figure:
    """``column`` against N for every sequence of ``scene``, with the predicted slopes drawn
    through the finest uniform and adaptive points."""
    figure = Figure(figsize=(7, 5))
    axes = figure.add_subplot()
    axes.set_xscale("log")
    axes.set_yscale("log")
    for key, group in _sequences(table, scene):
        _draw(axes, key, group["ndofs"], group[column])
    for strategy in ("uniform", "adaptive"):
        rows = table[(table["scene"] == scene) & (table["strategy"] == strategy)
                     & (table[column] > 0)]
        if rows.empty:
            continue
        slope = float(predicted[f"predicted_{strategy}"].iloc[0])
        last = rows.sort_values("ndofs").iloc[-1]
        n = np.array([last["ndofs"] / 30, last["ndofs"]])
        axes.loglog(n, last[column] * 1.5 * (n / n[-1]) ** slope, color="k",
                    linestyle="-" if strategy == "uniform" else "--", linewidth=2,
                    label=f"predicted {strategy}: N^{slope:.3f}")
    _finish(axes, "DOFs N", label, f"{scene}: {label}")
    return figure


def local_slope_figure(slopes: pd.DataFrame, scene: str, predicted: pd.DataFrame) -> Figure:
    """The local error slope between consecutive levels against N, with the predictions."""
    figure = Figure(figsize=(7, 4))
    axes = figure.add_subplot()
    axes.set_xscale("log")
    mine = slopes[slopes["scene"] == scene]
    for key, group in with_labels(mine).groupby(SEQUENCE):
        _draw(axes, key, np.sqrt(group["ndofs_from"] * group["ndofs_to"]), group["error_slope"])
    for strategy, style in (("uniform", "-"), ("adaptive", "--")):
        axes.axhline(float(predicted[f"predicted_{strategy}"].iloc[0]), color="k",
                     linestyle=style, linewidth=1.5, label=f"predicted {strategy}")
    axes.axhline(-0.25, color="grey", linestyle=":", label="paper: nearly O(h^1/2)")
    axes.set_ylim(-1.2, 0.2)
    _finish(axes, "DOFs N (geometric mean of the two levels)", "local slope of the error",
            f"{scene}: local error slopes")
    return figure


def effectivity_figure(table: pd.DataFrame, scene: str) -> Figure:
    """eta / ||u - u_h|| on every level of every sequence of ``scene``."""
    figure = Figure(figsize=(7, 4))
    axes = figure.add_subplot()
    axes.set_xscale("log")
    axes.set_yscale("log")
    for key, group in _sequences(table, scene):
        _draw(axes, key, group["ndofs"], group["effectivity_index"])
    _finish(axes, "DOFs N", "effectivity eta / ||u - u_h||",
            f"{scene}: effectivity on every level")
    return figure


def _claim_lines(asymptotic: pd.DataFrame) -> list[str]:
    """One line per scene and strategy: the range of the fitted error and eta slopes."""
    lines = []
    for (scene, strategy), rows in asymptotic.groupby(["scene", "strategy"], sort=True):
        line = (f"- {scene}, {strategy}: error slope {rows['error_slope'].min():.3f} .. "
                f"{rows['error_slope'].max():.3f}, eta slope {rows['eta_slope'].min():.3f} .. "
                f"{rows['eta_slope'].max():.3f} to {rows['ndofs_last'].max()} DOFs "
                f"(predicted asymptotically: {rows['predicted'].iloc[0]:.3f})")
        if strategy == "uniform" and rows["crossover_ndofs"].notna().any():
            line += (f"; singular share of e^2 at the last level "
                     f"{rows['singular_share'].min():.2f} .. {rows['singular_share'].max():.2f}"
                     f", equal shares near N = {rows['crossover_ndofs'].median():.2g}")
        lines.append(line)
    return lines


def _markdown(frame: pd.DataFrame) -> str:
    return frame.to_markdown(index=False, floatfmt=".4g") if len(frame) else "(no rows)"


def write_study_report(table: pd.DataFrame, out: str | Path, wall_seconds: float | None = None,
                       planned: int | None = None, gates: list[dict] | None = None,
                       results: str | Path | None = None) -> tuple[Path, list]:
    """README.md, tables as CSV and figures for the study's rows ``table``; with ``gates``
    (the ``[[study_gate]]`` entries of expected.toml) also their verdicts, returned too; with
    ``results`` (the study's results folder, for the artifacts) the seed's Figures 1 and 2."""
    out = Path(out)
    (out / "figures").mkdir(parents=True, exist_ok=True)
    slopes, asymptotic = local_slopes(table), asymptotic_table(table)
    scenes = sorted(table["scene"].unique())
    predicted = predictions(scenes, sorted(table["order"].unique()))
    nearly = nearly_half_range(slopes)
    verdicts = check_gates({"gate": gates}, [asymptotic]) if gates else []
    for name, frame in (("local-slopes", slopes), ("asymptotic", asymptotic),
                        ("predictions", predicted), ("nearly-half", nearly)):
        frame.to_csv(out / f"{name}.csv", index=False)
    figures = []
    for scene in scenes:
        mine = predicted[predicted["scene"] == scene]
        for kind, figure in (
                ("error", convergence_figure(table, scene, "energy_error", "energy error", mine)),
                ("eta", convergence_figure(table, scene, "eta", "eta", mine)),
                ("slopes", local_slope_figure(slopes, scene, mine)),
                ("effectivity", effectivity_figure(table, scene))):
            path = out / "figures" / f"{scene}-{kind}.png"
            figure.savefig(path, dpi=110, bbox_inches="tight")
            figures.append(path.name)
    seed = write_seed_figures(table, results, out / "figures") if results is not None else []
    text = _report_text(table, asymptotic, predicted, nearly, figures, wall_seconds, planned,
                        seed)
    if verdicts:
        text += ("\n## Gates\n\nThe `[[study_gate]]` entries of bench/verify/expected.toml.\n\n"
                 + verdict_table(verdicts) + "\n")
    (out / "README.md").write_text(text)
    return out / "README.md", verdicts


def _report_text(table, asymptotic, predicted, nearly, figures, wall_seconds, planned,
                 seed=()) -> str:
    columns = SHOWN + ["levels", "ndofs_last", "error_slope", "error_slope_se", "eta_slope",
                      "eta_slope_se", "pressure_slope", "pressure_slope_se", "predicted",
                      "singular_share", "crossover_ndofs", "effectivity_min", "effectivity_max",
                      "too_coarse_rows"]
    lines = ["# Rate study", "",
             f"{len(table)} levels of {table.groupby(KEYS, dropna=False).ngroups} sequences"
             + (f" (of {planned} planned)" if planned else "") + "; "
             f"{int(table['reference_too_coarse'].astype(bool).sum())} rows flagged "
             "`reference_too_coarse`. The levels' own phase times add up to "
             f"{phase_time(table).sum() / 60:.1f} min"
             + (f"; this invocation took {wall_seconds / 60:.1f} min (finished sequences of "
                "earlier runs are reused, not recomputed)." if wall_seconds else "."), "",
             "## Predictions", "",
             "Smallest singular exponent lambda of each scene (u ~ r^lambda; corners from "
             "their eigenvalue equation, contact-zone ends 3/2) and the slopes it predicts: "
             "uniform -min(lambda, p)/d, adaptive -p/d (h is N^(-1/d) in d dimensions).", "",
             _markdown(predicted), "",
             "## Asymptotic slopes", "",
             "Least-squares slopes over the last levels with their standard errors; "
             f"effectivity over every level from {EFFECTIVITY_FROM} DOFs. For uniform "
             "sequences, the two-term model e^2 = A N^-p + B N^-lambda fitted to the last "
             "levels gives the singular part's share of e^2 at the last level and the N at "
             "which it would equal the smooth part.", "", *_claim_lines(asymptotic), "",
             _markdown(asymptotic.reindex(columns=columns)), "",
             "## The seed paper's \"nearly O(h^1/2)\" under uniform refinement", "",
             f"Range of DOFs over which local error slopes are within {NEARLY} of -1/4, the "
             "range of all local slopes and the last one.",
             "", _markdown(nearly), ""]
    if seed:
        lines += ["## The seed's figures", "",
                  "Fig. 1: the adaptive mesh of the seed's setup (the mixed method, residual "
                  "estimator, lowest order) with its hanging nodes, and the von Mises stress "
                  "on the deformed body. Fig. 2: its estimated and true error under uniform "
                  "and adaptive refinement.", ""]
        lines += [f"![{name}](figures/{name})" for name in seed] + [""]
    lines += ["## Figures", ""]
    lines += [f"![{name}](figures/{name})" for name in figures]
    return "\n".join(lines) + "\n"

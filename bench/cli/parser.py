"""The command line's arguments: ``build_parser`` (the option types are in ``option_types``).
Every list of names comes from a registry."""

from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path

from bench.cli.generated import add_run_options
from bench.cli.option_types import (
    cell_list,
    name_list,
    non_negative_int,
)
from bench.cli.scaling_parser import add_scaling_parser
from bench.export import FORMATS, LEVELS
from bench.hard import hard_case_names
from bench.matrix.config import RunConfig
from bench.matrix.config_files import compare_settings
from bench.matrix.run import COMPARE_REFERENCE_DOFS, COMPARE_REFERENCE_DOFS_3D
from formulations.cells import DEFAULT_CELL, cell_names

NEGATIVE_NUMBER = re.compile(r"^-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$")


def with_negative_values(argv: list[str]) -> list[str]:
    """``--target-error -1e-3`` as ``--target-error=-1e-3``: argparse takes a token that starts
    with '-' and is not a plain negative number for an option ("expected one argument"), so
    the option's own check could not say what is allowed."""
    out: list[str] = []
    for token in argv:
        if out and NEGATIVE_NUMBER.match(token) and out[-1].startswith("--") \
                and "=" not in out[-1]:
            out[-1] = f"{out[-1]}={token}"
        else:
            out.append(token)
    return out


def _scene_file_option(parser) -> None:
    parser.add_argument("--scene-file", action="append", default=[], metavar="FILE",
                        help="a Python file that registers scenes with scenes.register_scene, or "
                             "a TOML scene (docs/scenes.md) (repeatable); its scenes join "
                             "--scene's choices")


def _config_options(parser, command: str) -> None:
    parser.add_argument("--config", default=None, metavar="FILE",
                        help=f"read the {command}'s options from a run file: TOML whose keys are "
                             "these options (max-dofs = 9000), or a results folder's run.json; "
                             "options given on the command line override its keys "
                             "(docs/command-line.md, \"Run files\")")
    parser.add_argument("--save-config", default=None, metavar="FILE",
                        help="write the run's full configuration to FILE as a run file before "
                             "running (run --config FILE repeats it)")


def _run_parser(sub, defaults: dict) -> None:
    run = sub.add_parser("run", help="run solve -> estimate -> mark -> refine sequences and "
                         "write results.parquet and results.csv",
                         description="Run every combination of the given comma-separated "
                         "lists and write one row per level to OUT/results.{parquet,csv}.")
    add_run_options(run, RunConfig, defaults)
    _no_overwrite_option(run, "keep every earlier result in OUT and reuse the sequences "
                         "finished with the same settings (the default; it wins over a run "
                         "file)")
    _config_options(run, "run")


def _no_overwrite_option(parser, help: str) -> None:
    parser.add_argument("--no-overwrite", action="store_true", help=help)


COMPARE_HELPS = {
    "out": "results folder, its own: a non-empty folder that compare did not write is "
           "refused without --overwrite",
    "overwrite": "replace the results of a folder that compare did not write (kept until the "
                 "new run has finished a sequence)",
    "crosscheck_dofs": "cross-check levels up to this size with the reference solver",
    "reference_dofs": ("DOF budget of the overkill references",
                       f"{COMPARE_REFERENCE_DOFS} for the P3 references in 2D, "
                       f"{COMPARE_REFERENCE_DOFS_3D} for the P2 references in 3D"),
    "cells": "cell shape(s), comma-separated: tri, quad; the whole comparison runs on each"}
COMPARE_OPTIONS = ("max_dofs", "cells", "reference_dofs", "max_memory_gib", "backend", "stopping",
                   "gamma_alg", "gamma_lin", "workers",
                   "scheduler", "cache", "scene_files", "crosscheck_dofs", "timing_repeats", "out",
                   "overwrite")


def _cell_option(parser, each: str) -> None:
    parser.add_argument("--cell", type=cell_list, default=[DEFAULT_CELL],
                        help=f"cell shape(s), comma-separated: {', '.join(cell_names())} (tri: "
                             "triangles, tetrahedra in 3D; quad: quadrilaterals with hanging "
                             f"nodes, hexahedra in 3D); {each} (default: {DEFAULT_CELL})")


def _report_parser(sub) -> None:
    report = sub.add_parser("report", help="render the report of a results folder",
                            description="Render OUT/README.md, OUT/index.html and "
                            "OUT/figures/*.png from RESULTS/results.parquet (and the hard "
                            "cases' RESULTS/hard.csv) without recomputing anything.")
    report.add_argument("--results", default="results",
                        help="folder holding results.parquet (default: results)")
    report.add_argument("--out", default="reports", help="report folder (default: reports)")


def _export_parser(sub) -> None:
    export = sub.add_parser("export", help="write each combination's fields (last level or "
                            "every level) for ParaView (meshio)",
                            description="Write, per combination of RESULTS, the mesh with the "
                            "displacement, stress tensor, von Mises stress, estimator "
                            "indicators and (exact truth) error density, and Gamma_C with "
                            "lambda_h and the gap, from RESULTS/artifacts (nothing recomputed).")
    export.add_argument("--results", default="results",
                        help="results folder with artifacts/ (default: results)")
    export.add_argument("--format", choices=list(FORMATS), default="vtu",
                        help="file format (default: vtu)")
    export.add_argument("--levels", choices=list(LEVELS), default="last",
                        help="last: each combination's last level; all: every level, plus one "
                             "series per combination that ParaView opens as one dataset "
                             "(.pvd for vtu, a temporal .xdmf collection for xdmf) "
                             "(default: last)")
    export.add_argument("--out", default=None,
                        help="folder for the files (default: RESULTS/fields)")


def _compare_parser(sub, defaults: dict) -> None:
    compare = sub.add_parser(
        "compare", help="the default comparison (the README's main job): run, hard, report",
        description="Run the default comparison: every scene not tagged hard x formulation x "
        "estimator, P1 uniform and adaptive, P2 and P3 adaptive (the parts of "
        "bench/matrix/compare.toml; --dim 3: compare-3d.toml) with the active-set solver "
        "(cross-checked by the reference on small levels), errors against exact solutions or "
        "cached overkill references; time the candidates to be the cheapest again; run every "
        "hard case into the same folder; render the report and print the recommendation per "
        "scene. --config FILE reads another run file.")
    settings = {**compare_settings(), **defaults}
    add_run_options(compare, RunConfig, settings, COMPARE_OPTIONS, COMPARE_HELPS)
    compare.add_argument("--dim", type=int, choices=(2, 3), default=settings["dim"],
                         help="the scenes' dimension (default: %(default)s); 3 runs the "
                              "tetrahedral scenes only, errors against exact solutions or P2 "
                              f"references (reference budget: {COMPARE_REFERENCE_DOFS} in 2D, "
                              f"{COMPARE_REFERENCE_DOFS_3D} in 3D, unless given)")
    compare.add_argument("--reports", default=settings.get("reports"),
                         help="report folder (default: OUT/report, inside the results "
                              "folder; give reports to regenerate the published report)")
    compare.add_argument("--quiet", action="store_true",
                         help="print nothing but the closing lines (no progress)")
    compare.add_argument("--readme", default=settings.get("readme"),
                         help="also replace the figures between the compare markers of this "
                              "README (e.g. README.md): rows, sequences, hard verdicts, time")
    _no_overwrite_option(compare, "keep the results of compare's own folder and reuse the "
                         "sequences it finished (resume an interrupted comparison) instead "
                         "of replacing them")
    _config_options(compare, "comparison")


def _verify_parser(sub) -> None:
    verify = sub.add_parser("verify", help="run the verification gates of expected.toml "
                            "and print a pass/fail table",
                            description="Run small sequences on the exact-solution scenes and "
                            "the paper scene (against a cached overkill reference), fit rates, "
                            "compute effectivity indices and the Hertz comparison, and check "
                            "every gate of bench/verify/expected.toml. Exit status 1 if any "
                            "fails.")
    verify.add_argument("--out", default="results-verify",
                        help="folder for the gate runs' results (default: results-verify)")
    verify.add_argument("--workers", type=non_negative_int("workers"), default=0,
                        help="run the gate sequences on a local Dask cluster of this many "
                             "processes (default: 0, in this process)")


def _hard_parser(sub) -> None:
    hard = sub.add_parser(
        "hard", help="run the hard cases and print their verdicts",
        description="Run every hard case (bench/hard) with every formulation and every "
        "solver, write OUT/hard.{csv,md}, and check each verdict against "
        "bench/verify/expected.toml. Exit status 1 if a verdict differs from the expected one.")
    hard.add_argument("--case", type=name_list("hard case", hard_case_names()), default=None,
                      help=f"case(s), comma-separated: {', '.join(hard_case_names())} "
                           "(default: all)")
    hard.add_argument("--out", default="results-hard",
                      help="folder for hard.csv and hard.md (default: results-hard)")
    _cell_option(hard, "the hard scenes run on each (the other cases on triangles)")

def program_name() -> str:
    """How the user started the command line: the console script names itself, anything
    else (``python -m bench``, a test) is ``python -m bench``."""
    script = Path(sys.argv[0]).name if sys.argv and sys.argv[0] else ""
    return "signorini-bench" if script == "signorini-bench" else "python -m bench"


def build_parser(defaults: dict | None = None) -> argparse.ArgumentParser:
    """The command line; ``defaults``: per command, field values of a run file that replace
    the fields' defaults (``--config``)."""
    defaults = defaults or {}
    parser = argparse.ArgumentParser(
        prog=program_name(),
        description="signorini-bench: compare formulations and a posteriori error estimators "
                    "for Signorini's contact problem.")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    _run_parser(sub, defaults.get("run", {}))
    _report_parser(sub)
    _export_parser(sub)
    add_scaling_parser(sub)
    _compare_parser(sub, defaults.get("compare", {}))
    _verify_parser(sub)
    _hard_parser(sub)
    from bench.cli.study import add_study_parser  # the study's own module (it uses these types)

    add_study_parser(sub, defaults.get("study"))
    from bench.cli.diff import add_diff_parser

    add_diff_parser(sub)
    from bench.cli.history import add_history_parser

    add_history_parser(sub)
    listing = sub.add_parser(
        "list", help="list registered scenes, formulations, solvers, back-ends, estimators and "
        "hard cases, with where each came from",
        description="List everything registered, with its origin (built-in, a scene file or "
        "an installed plugin) and one line of description; then any plugin that failed to "
        "load.")
    _scene_file_option(listing)
    return parser

"""The command line's arguments: ``build_parser`` (the option types are in ``option_types``).
Every list of names comes from a registry."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from bench.cli.option_types import (
    cell_list,
    gib,
    name_list,
    non_negative_int,
    order_list,
    positive_float,
    positive_int,
    scheduler_address,
    theta_value,
)
from bench.cli.scaling_parser import add_scaling_parser
from bench.export import FORMATS, LEVELS
from bench.hard import hard_case_names
from bench.matrix.run import COMPARE_REFERENCE_DOFS, COMPARE_REFERENCE_DOFS_3D
from bench.sequence.loop import STRATEGIES
from bench.sequence.marking import MARKINGS
from estimators import estimator_names
from formulations import formulation_names, solver_names
from formulations.cells import DEFAULT_CELL, cell_names
from formulations.elasticity import ORDERS
from formulations.solvers.backends import backend_names
from formulations.solvers.registry import FAST_SOLVER, REFERENCE_SOLVER
from scenes import scene_names
from scenes.registry import SCENES

COMPARE_OUT = "results-compare"  # compare's own folder: never the one run writes by default


def broken_scenes() -> dict[str, str]:
    """Why each scene that failed to load is left out (its origin and error)."""
    return {b.name: f"{b.origin}: {b.reason}" for b in SCENES.broken()}


def _scene_file_option(parser) -> None:
    parser.add_argument("--scene-file", action="append", default=[], metavar="FILE",
                        help="a Python file that registers scenes with scenes.register_scene, or "
                             "a TOML scene (docs/scenes.md) (repeatable); its scenes join "
                             "--scene's choices")


def _scale_out_options(parser) -> None:
    parser.add_argument("--workers", type=non_negative_int("workers"), default=0,
                        help="run the sequences on a local Dask cluster of this many processes "
                             "(one thread each) (default: 0, in this process)")
    parser.add_argument("--scheduler", type=scheduler_address, default=None,
                        metavar="ADDRESS",
                        help="run the sequences on the existing Dask cluster at ADDRESS, e.g. "
                             "tcp://10.0.0.5:8786 (its workers need this package and --cache "
                             "on shared storage); refused if no scheduler answers there within "
                             "10 s")
    parser.add_argument("--cache", default=None, metavar="DIR",
                        help="folder of the cached overkill references (default: "
                             "$SIGNORINI_BENCH_CACHE or .cache/references)")


def _memory_option(parser) -> None:
    parser.add_argument("--max-memory", type=gib, default=None, metavar="GIB",
                        help="refuse (status failed) a level whose predicted peak memory "
                             "exceeds this many GiB, before building it (default: the memory "
                             "the machine has available, minus 10 %% and at least 1 GiB)")


def _run_parser(sub) -> None:
    run = sub.add_parser("run", help="run solve -> estimate -> mark -> refine sequences and "
                         "write results.parquet and results.csv",
                         description="Run every combination of the given comma-separated "
                         "lists and write one row per level to OUT/results.{parquet,csv}.")
    run.add_argument("--scene", type=name_list("scene", scene_names(), sweep=True,
                                               broken=broken_scenes()),
                     default=["paper"],
                     help=f"scene(s), comma-separated; one of: {', '.join(scene_names())} "
                          "(default: paper); sweep parameters with name:key=v1|v2, e.g. "
                          "paper:poisson_ratio=0.3|0.45")
    run.add_argument("--formulation", type=name_list("formulation", formulation_names(),
                                                  sweep=True),
                     default=["mixed"], help="formulation(s): "
                     f"{', '.join(formulation_names())} (default: mixed); options as for "
                     "--scene, e.g. mixed:h_over_H=0.5|0.25")
    run.add_argument("--solver", type=name_list("solver", solver_names()),
                     default=[FAST_SOLVER],
                     help=f"solver(s): {', '.join(solver_names())} (default: {FAST_SOLVER}, "
                          f"the fast one; {REFERENCE_SOLVER} is the interior-point judge every "
                          "fast solve is checked against: --solver "
                          f"{FAST_SOLVER},{REFERENCE_SOLVER} runs both)")
    run.add_argument("--estimator", type=name_list("estimator", estimator_names()),
                     default=["residual"],
                     help=f"estimator(s): {', '.join(estimator_names())} (default: residual)")
    run.add_argument("--strategy", type=name_list("strategy", list(STRATEGIES), "strategies"),
                     default=["adaptive"],
                     help="refinement strategy(ies): uniform, adaptive (default: adaptive)")
    run.add_argument("--order", type=order_list, default=[1],
                     help="polynomial order(s) p of the displacements, comma-separated, from "
                          f"{', '.join(map(str, ORDERS))}; every formulation and estimator "
                          "runs at each (default: 1)")
    _cell_option(run, "every formulation and estimator runs on each")
    run.add_argument("--max-dofs", type=positive_int("max_dofs"), default=20000,
                     help="DOF budget: stop before a level with more unknowns (default: 20000)")
    run.add_argument("--max-levels", type=positive_int("max_levels"), default=40,
                     help="maximum number of levels (default: 40)")
    run.add_argument("--target-error", type=positive_float("target_error"), default=None,
                     metavar="TOL",
                     help="stop each sequence at the first level whose guaranteed error bound "
                          "is at most TOL (energy norm; needs a guaranteed estimator such as "
                          "equilibrated; default: off)")
    run.add_argument("--marking", choices=MARKINGS, default="doerfler",
                     help="adaptive marking: doerfler (bulk) or maximum (default: doerfler)")
    run.add_argument("--theta", type=theta_value, default=0.5,
                     help="marking parameter in (0, 1] (default: 0.5)")
    run.add_argument("--backend", choices=backend_names(), default=None,
                     help="sparse direct back-end of the active-set solver: pardiso (MKL, "
                          "installed with the package on x86_64), cholmod (needs scikit-sparse) "
                          "or splu (scipy) (default: the first of these that is available)")
    run.add_argument("--cold-start", action="store_true",
                     help="solve every level from scratch instead of starting from the "
                          "previous level's contact zone (nested iteration, the default)")
    run.add_argument("--reference-dofs", type=positive_int("reference_dofs"), default=None,
                     help="measure errors of scenes without an exact solution against a "
                          "cached adaptive P3 reference (mixed method) with at most this many "
                          "DOFs (default: only scenes with an exact solution get errors)")
    run.add_argument("--reference-crosscheck", action="store_true",
                     help="also build the P2 reference (twice the budget) and record its "
                          "agreement with the P3 one in truth.json (default: off)")
    _memory_option(run)
    _scale_out_options(run)
    _scene_file_option(run)
    run.add_argument("--crosscheck-dofs", type=non_negative_int("crosscheck_dofs"), default=0,
                     help="also solve levels with at most this many DOFs with the reference "
                          "solver and record the differences (default: 0, never)")
    run.add_argument("--out", default="results",
                     help="output folder for results.parquet and results.csv (default: results)")
    run.add_argument("--overwrite", action="store_true",
                     help="delete earlier results in OUT first (default: keep them, and reuse "
                          "every sequence an earlier run finished with the same settings)")


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


def _compare_parser(sub) -> None:
    compare = sub.add_parser(
        "compare", help="the default comparison (the README's main job): run, hard, report",
        description="Run every scene not tagged hard x formulation x estimator x {uniform, "
        "adaptive} with the active-set solver (cross-checked by the reference on small "
        "levels), errors against exact solutions or cached overkill references, then every "
        "hard case into the same folder, then render the report.")
    compare.add_argument("--max-dofs", type=positive_int("max_dofs"), default=20000,
                         help="DOF budget per sequence (default: 20000)")
    _cell_option(compare, "the whole comparison runs on each")
    compare.add_argument("--reference-dofs", type=positive_int("reference_dofs"),
                         default=None,
                         help="DOF budget of the overkill references (default: "
                              f"{COMPARE_REFERENCE_DOFS} for the P3 references in 2D, "
                              f"{COMPARE_REFERENCE_DOFS_3D} for the P2 references in 3D)")
    _memory_option(compare)
    _scale_out_options(compare)
    _scene_file_option(compare)
    compare.add_argument("--crosscheck-dofs", type=non_negative_int("crosscheck_dofs"),
                         default=3000, help="cross-check levels up to this size with the "
                         "reference solver (default: 3000)")
    compare.add_argument("--dim", type=int, choices=(2, 3), default=2,
                         help="the scenes' dimension (default: 2); 3 runs the tetrahedral "
                              "scenes only, errors against exact solutions or P2 references")
    compare.add_argument("--out", default=COMPARE_OUT,
                         help=f"results folder, its own: a non-empty folder that compare did "
                              f"not write is refused without --overwrite (default: "
                              f"{COMPARE_OUT})")
    compare.add_argument("--overwrite", action="store_true",
                         help="replace the results of a folder that compare did not write "
                              "(kept until the new run has finished a sequence)")
    compare.add_argument("--reports", default="reports", help="report folder (default: reports)")
    compare.add_argument("--readme", default=None,
                         help="also replace the figures between the compare markers of this "
                              "README (e.g. README.md): rows, sequences, hard verdicts, time")


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


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog=program_name(),
        description="signorini-bench: compare formulations and a posteriori error estimators "
                    "for Signorini's contact problem.")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    _run_parser(sub)
    _report_parser(sub)
    _export_parser(sub)
    add_scaling_parser(sub)
    _compare_parser(sub)
    _verify_parser(sub)
    _hard_parser(sub)
    from bench.cli.study import add_study_parser  # the study's own module (it uses these types)

    add_study_parser(sub)
    from bench.cli.diff import add_diff_parser

    add_diff_parser(sub)
    listing = sub.add_parser(
        "list", help="list registered scenes, formulations, solvers, back-ends, estimators and "
        "hard cases, with where each came from",
        description="List everything registered, with its origin (built-in, a scene file or "
        "an installed plugin) and one line of description; then any plugin that failed to "
        "load.")
    _scene_file_option(listing)
    return parser

"""Command line: ``python -m bench run|compare|report|scaling|verify|list``."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import pandas as pd

from bench.hard import CASES as HARD_CASES
from bench.loop import STRATEGIES, LevelResult, LoopConfig
from bench.marking import MARKINGS
from bench.matrix import run_matrix
from bench.rates import write_rates
from bench.report import write_report
from bench.rows import KEYS
from bench.scaling import SIZES, run_scaling, write_scaling
from bench.store import ResultStore
from estimators import estimator_descriptions, estimator_names
from formulations import (
    formulation_descriptions,
    formulation_names,
    solver_descriptions,
    solver_names,
)
from formulations.solvers.backends import BACKENDS, check_backend
from scenes import scene_descriptions, scene_names

SUMMARY_COLUMNS = ["level", "ndofs", "energy", "contact_force", "active_constraints", "eta",
                   "eta_0", "eta_geometric", "eta_complementarity", "energy_error",
                   "effectivity_index", "iterations", "t_solve", "status"]


def _names(kind: str, valid: list[str]):
    def parse(text: str) -> list[str]:
        names = [name.strip() for name in text.split(",") if name.strip()]
        unknown = [name for name in names if name not in valid]
        if not names or unknown:
            raise argparse.ArgumentTypeError(
                f"unknown {kind} {', '.join(map(repr, unknown)) or repr(text)}; "
                f"valid {kind}s: {', '.join(valid)}")
        return names
    return parse


def _positive_int(name: str):
    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            value = None
        if value is None or value <= 0:
            raise argparse.ArgumentTypeError(f"{name}={text!r} is not a positive integer")
        return value
    return parse


def _non_negative_int(name: str):
    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            value = -1
        if value < 0:
            raise argparse.ArgumentTypeError(f"{name}={text!r} is not an integer >= 0")
        return value
    return parse


def _theta(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not 0.0 < value <= 1.0:
        raise argparse.ArgumentTypeError(f"theta={text!r} is not a number in (0, 1]")
    return value


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="python -m bench",
        description="signorini-bench: compare formulations and a posteriori error estimators "
                    "for Signorini's contact problem.")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    run = sub.add_parser("run", help="run solve -> estimate -> mark -> refine sequences and "
                         "write results.parquet and results.csv",
                         description="Run every combination of the given comma-separated "
                         "lists and write one row per level to OUT/results.{parquet,csv}.")
    run.add_argument("--scene", type=_names("scene", scene_names()), default=["paper"],
                     help=f"scene(s), comma-separated; one of: {', '.join(scene_names())} "
                          "(default: paper)")
    run.add_argument("--formulation", type=_names("formulation", formulation_names()),
                     default=["mixed"], help="formulation(s): "
                     f"{', '.join(formulation_names())} (default: mixed)")
    run.add_argument("--solver", type=_names("solver", solver_names()), default=["reference"],
                     help=f"solver(s): {', '.join(solver_names())} (default: reference)")
    run.add_argument("--estimator", type=_names("estimator", estimator_names()),
                     default=["residual"],
                     help=f"estimator(s): {', '.join(estimator_names())} (default: residual)")
    run.add_argument("--strategy", type=_names("strategy", list(STRATEGIES)),
                     default=["adaptive"],
                     help="refinement strategy(ies): uniform, adaptive (default: adaptive)")
    run.add_argument("--max-dofs", type=_positive_int("max_dofs"), default=20000,
                     help="DOF budget: stop before a level with more unknowns (default: 20000)")
    run.add_argument("--max-levels", type=_positive_int("max_levels"), default=40,
                     help="maximum number of levels (default: 40)")
    run.add_argument("--marking", choices=MARKINGS, default="doerfler",
                     help="adaptive marking: doerfler (bulk) or maximum (default: doerfler)")
    run.add_argument("--theta", type=_theta, default=0.5,
                     help="marking parameter in (0, 1] (default: 0.5)")
    run.add_argument("--backend", choices=BACKENDS, default=None,
                     help="sparse direct back-end of the active-set solver: cholmod (needs "
                          "scikit-sparse) or splu (scipy) (default: cholmod when installed)")
    run.add_argument("--cold-start", action="store_true",
                     help="solve every level from scratch instead of starting from the "
                          "previous level's contact zone (nested iteration, the default)")
    run.add_argument("--reference-dofs", type=_positive_int("reference_dofs"), default=None,
                     help="measure errors of scenes without an exact solution against a "
                          "cached adaptive overkill reference with about this many DOFs "
                          "(default: only scenes with an exact solution get errors)")
    run.add_argument("--crosscheck-dofs", type=_non_negative_int("crosscheck_dofs"), default=0,
                     help="also solve levels with at most this many DOFs with the reference "
                          "solver and record the differences (default: 0, never)")
    run.add_argument("--out", default="results",
                     help="output folder for results.parquet and results.csv (default: results)")
    run.add_argument("--overwrite", action="store_true",
                     help="delete earlier results in OUT first (default: keep and append)")
    report = sub.add_parser("report", help="render the Markdown report of a results folder",
                            description="Render OUT/README.md and OUT/convergence.png from "
                            "RESULTS/results.parquet without recomputing anything.")
    report.add_argument("--results", default="results",
                        help="folder holding results.parquet (default: results)")
    report.add_argument("--out", default="reports", help="report folder (default: reports)")
    scaling = sub.add_parser(
        "scaling", help="time assembly, linear solve, fast and reference contact solves and "
        "the estimator against N, with peak memory",
        description="Measure every phase once per size, each size in a fresh process, and "
        "write OUT/scaling.{md,csv} (and the README's table with --readme).")
    scaling.add_argument("--sizes", type=_names("size", list(SIZES)), default=list(SIZES),
                         help=f"sizes, comma-separated: {', '.join(SIZES)} (default: all)")
    scaling.add_argument("--backend", choices=BACKENDS, default=None,
                         help="sparse back-end (default: cholmod when installed)")
    scaling.add_argument("--reference-max-dofs", type=_positive_int("reference_max_dofs"),
                         default=200_000, help="run the reference solver only up to this "
                         "many DOFs (default: 200000)")
    scaling.add_argument("--out", default="reports", help="output folder (default: reports)")
    scaling.add_argument("--readme", default=None,
                         help="also replace the table between the scaling markers of this "
                              "README (e.g. README.md)")
    compare = sub.add_parser(
        "compare", help="the default comparison (the README's main job): run, then report",
        description="Run every scene x formulation x estimator x {uniform, adaptive} with the "
        "active-set solver (cross-checked by the reference on small levels), errors against "
        "exact solutions or cached overkill references, then render the report.")
    compare.add_argument("--max-dofs", type=_positive_int("max_dofs"), default=20000,
                         help="DOF budget per sequence (default: 20000)")
    compare.add_argument("--reference-dofs", type=_positive_int("reference_dofs"),
                         default=500000, help="overkill reference size (default: 500000)")
    compare.add_argument("--crosscheck-dofs", type=_non_negative_int("crosscheck_dofs"),
                         default=3000, help="cross-check levels up to this size with the "
                         "reference solver (default: 3000)")
    compare.add_argument("--out", default="results", help="results folder (default: results)")
    compare.add_argument("--reports", default="reports", help="report folder (default: reports)")
    verify = sub.add_parser("verify", help="run the verification gates of bench/expected.toml "
                            "and print a pass/fail table",
                            description="Run small sequences on the exact-solution scenes and "
                            "the paper scene (against a cached overkill reference), fit rates, "
                            "compute effectivity indices and the Hertz comparison, and check "
                            "every gate of bench/expected.toml. Exit status 1 if any fails.")
    verify.add_argument("--out", default="results-verify",
                        help="folder for the gate runs' results (default: results-verify)")
    hard = sub.add_parser(
        "hard", help="run the hard cases and print their verdicts",
        description="Run every hard case (bench/hard.py) with every formulation and both "
        "solvers, write OUT/hard.{csv,md}, and check each verdict against bench/expected.toml. "
        "Exit status 1 if a verdict differs from the expected one.")
    hard.add_argument("--case", type=_names("hard case", list(HARD_CASES)), default=None,
                      help=f"case(s), comma-separated: {', '.join(HARD_CASES)} (default: all)")
    hard.add_argument("--out", default="results-hard",
                      help="folder for hard.csv and hard.md (default: results-hard)")
    sub.add_parser("list", help="list registered scenes, formulations, solvers, estimators",
                   description="List everything registered, with one line of description.")
    return parser


def _progress(result: LevelResult) -> None:
    r = result.row
    t = sum(x for x in (r.t_assemble, r.t_solve, r.t_estimate, r.t_refine) if x == x)
    print(f"{r.scene}/{r.formulation}/{r.solver}/{r.estimator}/{r.strategy} "
          f"level {r.level:2d}  ndofs {r.ndofs:8d}  eta {r.eta:11.5e}  time {t:7.2f} s  "
          f"{r.status}{' (' + r.reason + ')' if r.reason else ''}", flush=True)


def summary(table: pd.DataFrame) -> str:
    parts = []
    for key, group in table.groupby(KEYS, sort=False):
        parts.append("== " + " / ".join(map(str, key)))
        parts.append(group[SUMMARY_COLUMNS].to_string(index=False, float_format="{:.6g}".format))
    return "\n".join(parts)


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    if args.command == "list":
        for title, items in (("scenes", scene_descriptions()),
                             ("formulations", formulation_descriptions()),
                             ("solvers", solver_descriptions()),
                             ("estimators", estimator_descriptions())):
            print(f"{title}:")
            for name, text in items.items():
                print(f"  {name:12s} {text}")
        return 0
    if args.command == "scaling":
        def show(row):
            print(f"{row['size']}: ndofs {row['ndofs']}  fast {row['t_fast_solve']:.2f} s  "
                  f"linear {row['t_linear_solve']:.2f} s  reference "
                  f"{row['t_reference_solve']:.2f} s  peak {row['peak_gib']:.2f} GiB", flush=True)
        frame = run_scaling(args.sizes, args.backend, args.reference_max_dofs, on_row=show)
        print(f"wrote {write_scaling(frame, args.out, args.readme)}")
        return 0
    if args.command == "hard":
        return _hard(args.case, args.out)
    if args.command == "verify":
        from bench.verify import verdict_table
        from bench.verify import verify as run_verify

        verdicts, rates, hertz = run_verify(args.out, on_level=_progress)
        print("\n" + hertz.to_markdown(index=False, floatfmt=".4g") + "\n")
        print(verdict_table(verdicts))
        failed = [v for v in verdicts if not v.passed]
        print(f"\n{len(verdicts) - len(failed)} of {len(verdicts)} gates pass"
              f"{'' if not failed else '; FAILED: ' + ', '.join(sorted({v.gate for v in failed}))}")
        return 1 if failed else 0
    if args.command == "report":
        source = Path(args.results) / "results.parquet"
        if not source.exists():
            print(f"error: --results={args.results!r} holds no results.parquet", file=sys.stderr)
            return 2
        print(f"wrote {write_report(pd.read_parquet(source), args.out, args.results)}")
        return 0
    if args.command == "compare":
        return _compare(args)
    return _run(args, " ".join(["python -m bench", *(argv if argv is not None else
                                                       sys.argv[1:])]))


def _hard(cases, out) -> int:
    from bench.hard import run_hard
    from bench.hard_verdicts import check_expected, hard_markdown, write_hard
    from bench.verify import load_expected

    def show(name, frame):
        print(f"hard case {name}: {len(frame)} rows, verdicts "
              + ", ".join(f"{v} {n}" for v, n in frame["verdict"].value_counts().items()),
              flush=True)

    table = run_hard(cases, on_case=show)
    print(f"wrote {write_hard(table, out)}\n")
    print(hard_markdown(table))
    checks = check_expected(table, load_expected().get("hard", []))
    wrong = [c for c in checks if not c["passed"]]
    for c in wrong:
        print(f"UNEXPECTED: {c['case']}/{c['formulation']}/{c['solver']}/{c['variant']}: "
              f"{c['verdict']}, expected {c['expected']}")
    print(f"\n{len(checks) - len(wrong)} of {len(checks)} hard verdicts as expected")
    return 1 if wrong else 0


def _compare(args) -> int:
    from scenes import get_scene

    default_scenes = [n for n in scene_names() if "hard" not in get_scene(n).tags]
    argv = ["run", "--scene", ",".join(default_scenes), "--formulation",
            ",".join(formulation_names()), "--solver", "active-set", "--estimator",
            ",".join(estimator_names()), "--strategy", "uniform,adaptive", "--max-dofs",
            str(args.max_dofs), "--reference-dofs", str(args.reference_dofs),
            "--crosscheck-dofs", str(args.crosscheck_dofs), "--out", args.out, "--overwrite"]
    command = ("python -m bench compare (= python -m bench " + " ".join(argv)
               + f", then python -m bench hard --out {args.out})")
    status = _run(build_parser().parse_args(argv), command)
    hard_status = _hard(None, args.out)
    source = Path(args.out) / "results.parquet"
    print(f"wrote {write_report(pd.read_parquet(source), args.reports, args.out, command)}")
    return status or hard_status


def _run(args, command: str) -> int:
    if args.backend is not None:
        try:
            check_backend(args.backend)
        except ValueError as error:
            print(f"error: {error}", file=sys.stderr)
            return 2
    config = LoopConfig(max_dofs=args.max_dofs, max_levels=args.max_levels,
                        marking=args.marking, theta=args.theta, nested=not args.cold_start,
                        solver_options={"backend": args.backend} if args.backend else {})
    store = ResultStore(args.out, overwrite=args.overwrite)
    configuration = {k: v for k, v in vars(args).items() if k != "command"}
    (store.out / "run.json").write_text(json.dumps(
        {"command": command, "configuration": configuration}, indent=1, default=str))
    rows = run_matrix(args.scene, args.formulation, args.solver, args.estimator, args.strategy,
                      store, config, on_level=_progress, reference_dofs=args.reference_dofs,
                      crosscheck_dofs=args.crosscheck_dofs)
    print(f"wrote {write_rates(store.run_table(), store.out)}")
    print()
    print(summary(store.run_table()))
    print(f"\nwrote {len(rows)} rows to {store.parquet} and {store.csv}")
    failed = [r for r in rows if r.status == "failed"]
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())

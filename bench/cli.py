"""Command line: ``python -m bench run|compare|report|scaling|verify|hard|list`` (the commands;
the arguments are in ``bench.cli_parser``)."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pandas as pd

from bench.cli_parser import build_parser
from bench.loop import LevelResult, LoopConfig
from bench.matrix import run_matrix
from bench.rates import write_rates
from bench.report import write_report
from bench.rows import KEYS
from bench.scaling import run_scaling, write_scaling
from bench.store import ResultStore
from estimators import estimator_descriptions, estimator_names
from formulations import (
    formulation_descriptions,
    formulation_names,
    solver_descriptions,
)
from formulations.solvers.backends import check_backend
from scenes import scene_descriptions, scene_names

SUMMARY_COLUMNS = ["level", "ndofs", "energy", "contact_force", "active_constraints", "eta",
                   "eta_0", "eta_geometric", "eta_complementarity", "energy_error",
                   "effectivity_index", "iterations", "t_solve", "status"]


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

"""``python -m bench study``: its options and its command (docs/theory.md, section 10)."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pandas as pd

from bench.cli import option_types as options
from bench.cli.guards import InputError
from bench.study import QUICK, StudyConfig, run_study
from bench.study.quads import (
    QuadStudy,
    as_frame,
    hex_sequence,
    run_quad_study,
    write_hex_report,
    write_quad_report,
)
from bench.study.run import report_study
from scenes import scene_names

DEFAULTS = StudyConfig()
HEX_SCENE = "free-boundary-3d"  # the 3D scene with an exact solution


def add_study_parser(sub, settings: StudyConfig | None = None) -> None:
    """The study's options, their defaults from ``settings`` (a study file's, ``--config``) or
    the package's study.toml."""
    d = settings or DEFAULTS
    study = sub.add_parser(
        "study", help="the rate study: uniform sequences to 2e6 DOFs, adaptive to 1e6, every "
        "formulation x estimator, against sharp references; writes its own report",
        description="Run (or reuse) every sequence of the rate study into OUT, then write "
        "REPORT/README.md with local and asymptotic slopes, the predictions from the scenes' "
        "singular exponents and the effectivity on every level. A rerun reuses every finished "
        "sequence.")
    study.add_argument("--scene", type=options.name_list("scene", scene_names()),
                       default=None,
                       help=f"scene(s) (default: {','.join(d.scenes)}; with --cell hex: "
                            f"{HEX_SCENE})")
    study.add_argument("--order", type=options.order_list, default=list(d.orders),
                       help="polynomial order(s) (default: 1)")
    study.add_argument("--uniform-max-dofs", type=options.positive_int("uniform_max_dofs"),
                       default=d.uniform_max_dofs,
                       help=f"DOF budget of the uniform sequences "
                            f"(default: {d.uniform_max_dofs})")
    study.add_argument("--adaptive-max-dofs", type=options.positive_int("adaptive_max_dofs"),
                       default=d.adaptive_max_dofs,
                       help=f"DOF budget of the adaptive sequences "
                            f"(default: {d.adaptive_max_dofs})")
    study.add_argument("--reference-dofs", type=options.positive_int("reference_dofs"),
                       default=d.reference_dofs,
                       help=f"P3 reference budget (default: {d.reference_dofs})")
    study.add_argument("--workers", type=options.non_negative_int("workers"),
                       default=d.workers,
                       help=f"adaptive sequences run in parallel on a local Dask cluster of "
                            f"this many processes; uniform ones one at a time "
                            f"(default: {d.workers})")
    study.add_argument("--cell", choices=("tri", "quad", "hex"), default="tri",
                       help="tri (default): the matrix's formulations on triangles; quad: the "
                            "seed's own discretisation, Q1 (Q2 with --order 2) on hierarchical "
                            "quadrilateral meshes with hanging nodes, vi and the mixed method "
                            "with lambda_H one and two levels coarser, the seed's residual "
                            "estimator (REPORT/quads.md); hex: Q1 on the 3D scenes' cubes, "
                            "vi, uniform (REPORT/hexes.md)")
    study.add_argument("--quick", action="store_true",
                       help=f"the reduced study of the default tests ([quick] of study.toml): "
                            f"{','.join(QUICK.scenes)}, uniform to {QUICK.uniform_max_dofs} and "
                            f"adaptive to {QUICK.adaptive_max_dofs} DOFs, {QUICK.workers} "
                            "workers")
    study.add_argument("--report-only", action="store_true",
                       help="write the report of the sequences finished so far in OUT, "
                            "without running anything")
    study.add_argument("--out", default=d.out,
                       help=f"results folder (default: {d.out})")
    study.add_argument("--report", default=d.report,
                       help=f"report folder (default: {d.report})")
    study.add_argument("--config", default=None, metavar="FILE",
                       help="read the study's settings from FILE, a copy of the package's "
                            "bench/study/study.toml (its keys: scenes, orders, "
                            "uniform-max-dofs, ...); options given override them")
    study.set_defaults(study_scenes=d.scenes, study_crosscheck=d.crosscheck)


def quad_study_command(args) -> int:
    """``study --cell quad``: the quadrilateral sequences and their report."""
    orders = tuple(o for o in args.order if o in (1, 2))
    if len(orders) < len(args.order):
        raise InputError(f"--order={','.join(map(str, args.order))}: quadrilaterals run "
                         "orders 1 and 2")
    study = QuadStudy(scenes=tuple(args.scene or DEFAULTS.scenes), orders=orders,
                      uniform_max_dofs=9000 if args.quick else args.uniform_max_dofs,
                      adaptive_max_dofs=5000 if args.quick else args.adaptive_max_dofs,
                      reference_dofs=args.reference_dofs)

    if args.report_only:  # the report again from the levels of the last run
        csv = Path(args.report) / "quads.csv"
        if not csv.is_file():
            raise InputError(f"--report={args.report!r} holds no quads.csv; run "
                             "study --cell quad first")
        table = pd.read_csv(csv)
        print(f"wrote {write_quad_report(table, args.report, read_command(args.report), 20000)}")
        return 0

    def show(rows):
        last = rows[-1]
        print(f"{last.scene}/{last.method}/Q{last.order}/{last.strategy}: {len(rows)} "
              f"levels to {last.ndofs} DOFs, error {last.energy_error:.4g}, eta "
              f"{last.eta:.4g}", flush=True)

    try:
        table = run_quad_study(study, show)
    except ValueError as error:
        raise InputError(str(error)) from None
    report = write_quad_report(table, args.report, " ".join(["python -m bench", *args.argv]),
                               min(study.adaptive_max_dofs, 20000))
    print(f"{len(table)} levels; wrote {report}")
    return 0


def hex_study_command(args) -> int:
    """``study --cell hex``: uniform Q1 on hexahedra of the 3D scenes given (default:
    free-boundary-3d) and its report."""
    scenes = args.scene or [HEX_SCENE]
    budget = 30000 if args.quick else args.uniform_max_dofs
    rows = []
    try:
        for scene in scenes:
            rows += hex_sequence(scene, budget)
            print(f"{scene}/vi/hex-Q1/uniform: {len(rows)} levels", flush=True)
    except ValueError as error:
        raise InputError(str(error)) from None
    report = write_hex_report(as_frame(rows), args.report,
                              " ".join(["python -m bench", *args.argv]))
    print(f"{len(rows)} levels; wrote {report}")
    return 0


def read_command(folder) -> str:
    """The command line recorded in an earlier FOLDER/quads.md ('' if none)."""
    path = Path(folder) / "quads.md"
    lines = path.read_text().splitlines() if path.is_file() else []
    return next((line.strip("`") for line in lines if line.startswith("`python -m bench")), "")


def study_command(args) -> int:
    if args.cell == "quad":
        return quad_study_command(args)
    if args.cell == "hex":
        return hex_study_command(args)
    base = QUICK if args.quick else StudyConfig(
        scenes=tuple(args.scene or args.study_scenes), orders=tuple(args.order),
        uniform_max_dofs=args.uniform_max_dofs, adaptive_max_dofs=args.adaptive_max_dofs,
        reference_dofs=args.reference_dofs, workers=args.workers,
        crosscheck=args.study_crosscheck)
    config = dataclasses.replace(base, out=args.out, report=args.report,
                                 command=" ".join(["python -m bench", *args.argv]))
    if args.report_only:
        try:
            table, report, verdicts = report_study(config)
        except ValueError as error:
            raise InputError(str(error)) from None
    else:
        table, report, verdicts = run_study(config)
    failed = [v for v in verdicts if not v.passed]
    print(f"{len(table)} levels; wrote {report}"
          + (f"; {len(verdicts) - len(failed)} of {len(verdicts)} study gates pass"
             if verdicts else ""))
    return 1 if failed else 0

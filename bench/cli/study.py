"""``python -m bench study``: its options and its command (docs/theory.md, section 10)."""

from __future__ import annotations

import dataclasses

import bench.cli.option_types as options
from bench.cli.guards import InputError
from bench.study import QUICK, StudyConfig, run_study
from bench.study.run import STUDY_FILE, StudyFile, report_study
from formulations.cells import family_for
from scenes import get_scene, scene_names

DEFAULTS = STUDY_FILE.settings
# the options a study file also sets: field -> flag (given ones override the file)
STUDY_FLAGS = {"scenes": "scene", "orders": "order", "uniform_max_dofs": "uniform-max-dofs",
               "adaptive_max_dofs": "adaptive-max-dofs", "reference_dofs": "reference-dofs",
               "workers": "workers", "out": "out", "report": "report"}


def add_study_parser(sub, study_file: StudyFile | None = None) -> None:
    """The study's options, their defaults from ``study_file`` (``--config``) or the
    package's study.toml."""
    study_file = study_file or STUDY_FILE
    d = study_file.settings
    study = sub.add_parser(
        "study", help="the rate study: uniform sequences to 2e6 DOFs, adaptive to 1e6, every "
        "formulation x estimator, against sharp references; writes its own report",
        description="Run (or reuse) every sequence of the rate study into OUT, then write "
        "REPORT/README.md with local and asymptotic slopes, the predictions from the scenes' "
        "singular exponents and the effectivity on every level. A rerun reuses every finished "
        "sequence.")
    study.add_argument("--scene", type=options.name_list("scene", scene_names()),
                       default=None,
                       help=f"scene(s) (default: {','.join(d.scenes)}; with --cell quad or hex: "
                            "the study file's [cells.NAME] table's)")
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
    study.add_argument("--cell", choices=study_file.cell_names(), default=d.cell,
                       help="tri (default): every formulation x estimator on triangles; quad: "
                            "the study file's [cells.quad] table, the seed's own discretisation "
                            "(Q1, Q2 with --order 2, on hierarchical quadrilateral meshes with "
                            "hanging nodes, vi and the mixed method with lambda_H one and two "
                            "levels coarser, the residual estimator), run by the matrix, with "
                            "the seed's Fig. 1 and Fig. 2 in the report; hex: [cells.hex], Q1 on "
                            "the hexahedra of a 3D scene's grid of cubes, uniform, every "
                            "formulation with a contact space on quadrilateral faces")
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
    study.set_defaults(study_file=study_file)


def study_config(args) -> StudyConfig:
    """The study the command line asks for: the study file's settings on ``--cell`` (reduced
    by ``--quick``), then the options given on the command line."""
    config = args.study_file.config(args.cell, quick=args.quick)
    given = {name for name, flag in STUDY_FLAGS.items()
             if any(a == f"--{flag}" or a.startswith(f"--{flag}=") for a in args.argv)}
    values = dict(scenes=tuple(args.scene or ()), orders=tuple(args.order),
                  uniform_max_dofs=args.uniform_max_dofs,
                  adaptive_max_dofs=args.adaptive_max_dofs,
                  reference_dofs=args.reference_dofs, workers=args.workers, out=args.out,
                  report=args.report)
    config = dataclasses.replace(config, **{name: values[name] for name in given},
                                 command=" ".join(["python -m bench", *args.argv]))
    for scene in config.scenes:  # a cell without the element is refused, not a skipped study
        family = family_for(config.cell, get_scene(scene).dim)
        why = next(filter(None, map(family.why_no_element, config.orders)), None)
        if why is not None:
            raise InputError(f"--order={','.join(map(str, config.orders))}: {why}")
    return config


def study_command(args) -> int:
    try:
        config = study_config(args)
    except ValueError as error:
        raise InputError(str(error)) from None
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

"""``python -m bench study``: its options and its command (docs/theory.md, section 10)."""

from __future__ import annotations

import dataclasses

from bench.cli.generated import add_run_options, given_options, run_values
from bench.cli.guards import InputError
from bench.sequence.options import option_fields
from bench.study import QUICK, StudyConfig, run_study
from bench.study.run import STUDY_FILE, StudyFile, report_study
from formulations.cells import family_for
from scenes import get_scene


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
    # every setting that is an option, its default the study file's (the scenes: its
    # [cells.NAME] table's, so none here)
    add_run_options(study, StudyConfig, defaults={
        **{f.name: getattr(d, f.name) for f, _ in option_fields(StudyConfig)}, "scenes": ()})
    study.add_argument("--cell", choices=study_file.cell_names(), default=d.cell,
                       help="tri (default): every formulation x estimator on triangles; quad: "
                            "the study file's [cells.quad] table, the seed's own discretisation "
                            "(Q1, Q2 with --order 2, on hierarchical quadrilateral meshes with "
                            "hanging nodes, vi and the mixed method with lambda_H one and two "
                            "levels coarser, the residual estimator), run by the matrix, with "
                            "the seed's Fig. 1 and Fig. 2 in the report; hex: [cells.hex], Q1 (Q2 "
                            "with --order 2) on the hexahedra of a 3D scene's grid of cubes, "
                            "uniform and adaptive with hanging nodes, every formulation with a "
                            "contact space on quadrilateral faces, averaging and residual")
    study.add_argument("--quick", action="store_true",
                       help=f"the reduced study of the default tests ([quick] of study.toml): "
                            f"{','.join(QUICK.scenes)}, uniform to {QUICK.uniform_max_dofs} and "
                            f"adaptive to {QUICK.adaptive_max_dofs} DOFs, {QUICK.workers} "
                            "workers")
    study.add_argument("--report-only", action="store_true",
                       help="write the report of the sequences finished so far in OUT, "
                            "without running anything")
    study.add_argument("--config", default=None, metavar="FILE",
                       help="read the study's settings from FILE, a copy of the package's "
                            "bench/study/study.toml (its keys: scenes, orders, "
                            "uniform-max-dofs, ...); options given override them")
    study.set_defaults(study_file=study_file)


def study_config(args) -> StudyConfig:
    """The study the command line asks for: the study file's settings on ``--cell`` (reduced
    by ``--quick``), then the options given on the command line."""
    config = args.study_file.config(args.cell, quick=args.quick)
    given = given_options(args, StudyConfig)
    values = run_values(args, StudyConfig)
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

"""The commands of ``python -m bench``, dispatched from ``COMMANDS`` (the arguments are in
``bench.cli.parser``). Exit status: 0 success, 1 a failed row, gate or unexpected verdict,
2 bad input."""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path

import pandas as pd

from bench.cli.compare_block import check_readme, write_compare_block
from bench.cli.diff import diff_command
from bench.cli.guards import InputError, check_compare_out, check_output_folders
from bench.cli.listing import list_command
from bench.cli.parser import build_parser
from bench.cli.progress import Progress
from bench.cli.study import study_command
from bench.export import export_results
from bench.hard import (
    check_expected,
    hard_markdown,
    hard_scene_names,
    run_hard,
    write_hard,
)
from bench.matrix import RunConfig, run
from bench.matrix.plugins import load_plugins
from bench.matrix.run import RunRefused, compare_reference_dofs
from bench.matrix.scene_files import load_scene_files, scene_files_in
from bench.matrix.store import ResultsError, read_results
from bench.perf.scaling import SIZES, run_scaling, write_scaling
from bench.perf.scaling_3d import SIZES_3D, run_scaling_3d, write_scaling_3d
from bench.perf.sequence import SEQUENCES, run_sequences, write_sequences
from bench.report import write_report
from bench.sequence.loop import LevelResult
from bench.sequence.rows import KEYS, level_time
from bench.verify import load_expected, verdict_table, verify
from estimators import estimator_names
from formulations import formulation_names
from formulations.solvers.backends import check_backend
from formulations.solvers.registry import FAST_SOLVER
from scenes import get_scene, scene_names
from scenes.registry import SCENES, scene_dim

SUMMARY_COLUMNS = ["level", "ndofs", "energy", "contact_force", "active_constraints", "eta",
                   "eta_0", "eta_geometric", "eta_complementarity", "energy_error",
                   "effectivity_index", "iterations", "t_solve", "status"]


def progress(result: LevelResult) -> None:
    r = result.row
    print(f"{r.scene}/{r.formulation}/{r.solver}/{r.estimator}/{r.strategy} "
          f"level {r.level:2d}  ndofs {r.ndofs:8d}  eta {r.eta:11.5e}  "
          f"time {level_time(r):7.2f} s  "
          f"{r.status}{' (' + r.reason + ')' if r.reason else ''}", flush=True)


def summary(table: pd.DataFrame) -> str:
    parts = []
    for key, group in table.groupby(KEYS, sort=False, dropna=False):
        parts.append("== " + " / ".join(str(k) for k in key if str(k)))
        parts.append(group[SUMMARY_COLUMNS].to_string(index=False, float_format="{:.6g}".format))
    return "\n".join(parts)


def configured(**fields) -> RunConfig | None:
    """The run's configuration, or None after printing why it is refused."""
    try:
        return RunConfig(**fields)
    except ValueError as error:
        print(f"error: {error}", file=sys.stderr)
        return None


def run_config(config: RunConfig | None) -> int:
    if config is None:
        return 2
    live = Progress(len(config.specs()))
    result = run(config, on_level=live.level(progress), on_sequence=live.sequence)
    live.close()
    if result.reused:
        print(f"reused {len(result.reused)} sequences finished by an earlier run in "
              f"{result.store.out}")
    print(f"wrote {result.store.out / 'rates.md'}\n")
    print(summary(result.table))
    print(f"\nwrote {len(result.rows)} rows to {result.store.parquet} and {result.store.csv}")
    return 1 if result.failed else 0


def run_command(args) -> int:
    config = configured(
        scenes=args.scene, formulations=args.formulation, solvers=args.solver,
        estimators=args.estimator, strategies=args.strategy, orders=args.order,
        cells=args.cell, max_dofs=args.max_dofs,
        max_levels=args.max_levels, marking=args.marking, theta=args.theta,
        backend=args.backend, nested=not args.cold_start, reference_dofs=args.reference_dofs,
        reference_crosscheck=args.reference_crosscheck, crosscheck_dofs=args.crosscheck_dofs,
        max_memory_gib=args.max_memory, out=args.out,
        overwrite=args.overwrite, workers=args.workers, scheduler=args.scheduler,
        cache=args.cache, scene_files=tuple(args.scene_file), target_error=args.target_error,
        command=" ".join(["python -m bench", *args.argv]))
    return run_config(config)


def hard_command(args) -> int:
    def show(name, frame):
        print(f"hard case {name}: {len(frame)} rows, verdicts "
              + ", ".join(f"{v} {n}" for v, n in frame["verdict"].value_counts().items()),
              flush=True)

    table = run_hard(args.case, on_case=show, cells=args.cell)
    print(f"wrote {write_hard(table, args.out)}\n")
    print(hard_markdown(table))
    checks = check_expected(table, load_expected().get("hard", []))
    wrong = [c for c in checks if not c["passed"]]
    for c in wrong:
        print(f"UNEXPECTED: {c['case']}/{c['formulation']}/{c['solver']}/{c['variant']}: "
              f"{c['verdict']}, expected {c['expected']}")
    print(f"\n{len(checks) - len(wrong)} of {len(checks)} hard verdicts as expected")
    return 1 if wrong else 0


def compared_scenes(dim: int) -> list[str]:
    """The scenes of ``compare``: every scene not tagged hard of dimension ``dim``. A scene
    whose registration does not declare its dimension is built to learn it; one that fails
    to build is named once on stderr and left out."""
    names, hard = [], set(hard_scene_names())
    for name in scene_names():
        if name in hard:
            continue
        known = scene_dim(name)
        if known is None:
            try:
                known = get_scene(name).dim
            except Exception as error:  # a user's scene: name it, leave it out, go on
                SCENES.mark_broken(name, f"{type(error).__name__}: {error}")
                print(f"warning: scene {name!r} fails to build and is left out: "
                      f"{type(error).__name__}: {error}", file=sys.stderr)
                continue
        if known == dim:
            names.append(name)
    return names


def compare_command(args) -> int:
    """The default comparison: every scene not tagged hard x every formulation x every
    estimator x {uniform, adaptive} with the active-set solver, then the hard cases into the
    same folder, then the report."""
    check_compare_out(args.out, args.overwrite)
    config = configured(
        scenes=compared_scenes(args.dim),
        formulations=formulation_names(), solvers=(FAST_SOLVER,),
        estimators=estimator_names(), strategies=("uniform", "adaptive"), cells=args.cell,
        max_dofs=args.max_dofs,
        reference_dofs=compare_reference_dofs(args.reference_dofs, args.dim),
        crosscheck_dofs=args.crosscheck_dofs, max_memory_gib=args.max_memory, out=args.out,
        overwrite=True, workers=args.workers, scheduler=args.scheduler, cache=args.cache,
        scene_files=tuple(args.scene_file), command=" ".join(["python -m bench", *args.argv]))
    if args.readme is not None:
        try:
            check_readme(args.readme)
        except ValueError as error:
            raise InputError(str(error)) from None
    start = time.perf_counter()
    status = run_config(config)
    if config is None:
        return status
    args.case = None
    hard_status = hard_command(args) if args.dim == 2 else 0  # the hard cases are 2D
    print(f"wrote {write_report(read_results(args.out), args.reports, args.out)}")
    if args.readme is not None:
        write_compare_block(args.readme, args.out, time.perf_counter() - start)
        print(f"wrote the compare figures into {args.readme}")
    return status or hard_status


def report_command(args) -> int:
    table = read_results(args.results)
    if table is None:
        print(f"error: --results={args.results!r} holds no results.parquet", file=sys.stderr)
        return 2
    print(f"wrote {write_report(table, args.out, args.results)}")
    return 0


def export_command(args) -> int:
    if args.out is None:
        args.out = str(Path(args.results) / "fields")
    if not (Path(args.results) / "artifacts").is_dir():
        raise InputError(f"--results={args.results!r} holds no artifacts/ (written by run and "
                         "compare); give a results folder")
    try:
        written = export_results(args.results, args.out, args.format, args.levels)
    except ValueError as error:
        raise InputError(f"--{error}") from None
    print(f"wrote {len(written)} files to {args.out}")
    return 0


def verify_command(args) -> int:
    verdicts, _, closed_form = verify(args.out, on_level=progress, workers=args.workers)
    print("\n" + closed_form.to_markdown(index=False, floatfmt=".4g") + "\n")
    print(verdict_table(verdicts))
    failed = [v for v in verdicts if not v.passed]
    print(f"\n{len(verdicts) - len(failed)} of {len(verdicts)} gates pass"
          f"{'' if not failed else '; FAILED: ' + ', '.join(sorted({v.gate for v in failed}))}")
    return 1 if failed else 0


def scaling_command(args) -> int:
    def show(row):
        print(f"{row['size']} P{row['order']}: ndofs {row['ndofs']}  "
              f"fast {row['t_fast_solve']:.2f} s  "
              f"linear {row['t_linear_solve']:.2f} s  reference "
              f"{row['t_reference_solve']:.2f} s  peak {row['peak_gib']:.2f} GiB", flush=True)
    try:
        check_backend(args.backend)
    except ValueError as error:
        raise InputError(f"--backend: {error}") from None
    if args.sequence:
        return sequence_command(args)
    sizes = args.sizes or list(SIZES_3D if args.dim == 3 else SIZES)
    allowed = SIZES_3D if args.dim == 3 else SIZES
    wrong = [size for size in sizes if size not in allowed]
    if wrong:
        raise InputError(f"--sizes={','.join(wrong)} is not one of {', '.join(allowed)} "
                         f"in {args.dim}D")
    if args.dim == 3:
        frame = run_scaling_3d(sizes, args.backend, args.order, on_row=show_3d)
        print(f"wrote {write_scaling_3d(frame, args.out, args.readme)}")
        return 0
    frame = run_scaling(sizes, args.backend, args.reference_max_dofs, on_row=show,
                        orders=args.order)
    print(f"wrote {write_scaling(frame, args.out, args.readme)}")
    return 0


def show_3d(row) -> None:
    print(f"{row['size']} P{row['order']} 3D: ndofs {row['ndofs']}  assembly "
          f"{row['t_assemble']:.2f} s  linear {row['t_linear_solve']:.2f} s  fast "
          f"{row['t_fast_solve']:.2f} s  peak {row['peak_gib']:.2f} GiB", flush=True)


def sequence_command(args) -> int:
    def show(row):
        print(f"{row['strategy']} to {row['max_dofs']} ({row['cell']}): {row['levels']} levels, "
              f"finest "
              f"{row['final_ndofs']} DOFs, {row['t_sequence']:.1f} s = "
              f"{row['sequence_over_linear']:.1f} linear solves at the finest level", flush=True)
    budgets = zip([s for s, _ in SEQUENCES], args.sequence_max_dofs, strict=True)
    frame = run_sequences(list(budgets), args.backend, on_row=show, cells=args.cell)
    print(f"wrote {write_sequences(frame, args.out, args.readme)}")
    return 0


COMMANDS = {"run": run_command, "compare": compare_command, "report": report_command,
            "export": export_command,
            "verify": verify_command, "hard": hard_command, "scaling": scaling_command,
            "list": list_command, "study": study_command,
            "diff": diff_command}


def main(argv: list[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    load_plugins()  # before the parser too: its lists include the plugins' units
    try:  # before the parser: its lists of valid scenes include the files' scenes
        load_scene_files(scene_files_in(argv))  # a file that fails is named and left out
    except ValueError as error:  # a path that is not a scene file
        print(f"error: {error}", file=sys.stderr)
        return 2
    args = build_parser().parse_args(argv)
    args.argv = argv
    try:
        check_output_folders(args.command, args)
        return COMMANDS[args.command](args)
    except (InputError, ResultsError, RunRefused) as error:
        print(f"error: {error}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # the reader went away (e.g. `| head`): stop quietly
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 1
    except KeyboardInterrupt:
        print(f"interrupted: every finished row is kept in {getattr(args, 'out', 'the output')}"
              " (results.parquet, results.csv)", file=sys.stderr)
        return 130

"""The commands of ``python -m bench``, dispatched from ``COMMANDS`` (the arguments are in
``bench.cli.parser``). Exit status: 0 success, 1 a failed row, gate or unexpected verdict,
2 bad input or a full disk, 128 + N when signal N ended it (docs/reliability.md)."""

from __future__ import annotations

import os
import sys
import time
from dataclasses import replace
from pathlib import Path

import pandas as pd

from bench.cli.compare_block import check_readme, write_compare_block
from bench.cli.diff import diff_command
from bench.cli.generated import given_options, run_values
from bench.cli.guards import (
    InputError,
    check_compare_out,
    check_output_folder,
    check_output_folders,
    full_disk,
)
from bench.cli.history import history_command
from bench.cli.listing import list_command
from bench.cli.parser import build_parser, with_negative_values
from bench.cli.progress import progress
from bench.cli.run_files import overwrite_of, run_file_defaults
from bench.cli.running import command_line, configured, run_config, save_config
from bench.cli.scaling_commands import scaling_command
from bench.cli.signals import ended_line, ending_signals, exit_status
from bench.cli.study import study_command
from bench.export import export_results
from bench.hard import (
    check_expected,
    hard_markdown,
    hard_scene_names,
    run_hard,
    write_hard,
)
from bench.matrix import RunConfig
from bench.matrix.config_files import (
    COMPARE_KEYS,
    compare_settings,
)
from bench.matrix.files import FULL
from bench.matrix.plugins import load_plugins
from bench.matrix.run import RunRefused, cached_reference_dofs, compare_reference_dofs
from bench.matrix.scene_files import load_scene_files, scene_files_in
from bench.matrix.store import ResultsError, read_results
from bench.report import write_report
from bench.report.console import console_summary, duration
from bench.report.render import read_json
from bench.verify import load_expected, verdict_table, verify
from bench.verify.expected import ExpectedError
from estimators import estimator_names
from formulations import formulation_names
from scenes import get_scene, scene_names
from scenes.registry import SCENES, scene_dim


def run_command(args) -> int:
    values = {**run_values(args, RunConfig), "overwrite": overwrite_of(args, False)}
    config = configured(**values, command=command_line(args))
    if config is not None and config.reference_dofs is None:
        try:
            cached = cached_reference_dofs(config)
        except ValueError:  # a bad scene parameter: the run refuses it, naming it
            cached = None
        if cached is not None:
            print(f"note: errors measured against the references compare cached (as with "
                  f"--reference-dofs {cached}; give --reference-dofs to choose another)",
                  file=sys.stderr)
            config = replace(config, reference_dofs=cached)
    save_config(config, args)
    return run_config(config)


def hard_command(args, compare: bool = False) -> int:
    """Run the hard cases; ``compare``: one line for them all (compare prints the verdict
    counts and the unexpected rows last)."""
    def show(name, frame):
        if not compare:
            print(f"hard case {name}: {len(frame)} rows, verdicts "
                  + ", ".join(f"{v} {n}" for v, n in frame["verdict"].value_counts().items()),
                  flush=True)

    expected = load_expected().get("hard", [])  # a damaged file is named before any work
    start = time.perf_counter()
    table = run_hard(args.case, on_case=show, cells=args.cell)
    written = write_hard(table, args.out)
    checks = check_expected(table, expected)
    wrong = [c for c in checks if not c["passed"]]
    if compare:
        if not getattr(args, "quiet", False):
            print(f"ran {table['case'].nunique()} hard cases ({len(table)} rows) in "
                  f"{duration(time.perf_counter() - start)} into {written}", flush=True)
        return 1 if wrong else 0
    print(f"wrote {written}")
    print("\n" + hard_markdown(table))
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


def compare_fields(args) -> dict:
    """compare's run: its package settings, then the run file's keys (``--config``), then
    its options; scenes, formulations and estimators not given are every registered one."""
    fields = {k: v for k, v in {**compare_settings(dim=args.dim), **args.file_fields}.items()
              if k not in COMPARE_KEYS}
    fields.update(run_values(args, RunConfig))
    given = given_options(args, RunConfig)  # the command line's last word, over the parts too
    fields["parts"] = tuple(tuple((k, v) for k, v in (part.items() if isinstance(part, dict)
                                                      else part) if k not in given)
                            for part in fields.get("parts", ()))
    fields.setdefault("scenes", compared_scenes(args.dim))
    fields.setdefault("formulations", formulation_names())
    fields.setdefault("estimators", estimator_names())
    fields["reference_dofs"] = compare_reference_dofs(fields.get("reference_dofs"), args.dim)
    # its own folder (check_compare_out decided): replaced unless --no-overwrite
    return {**fields, "overwrite": overwrite_of(args, True)}


def compare_command(args) -> int:
    """The default comparison: every scene not tagged hard x every formulation x every
    estimator x {uniform, adaptive} with the active-set solver (``compare.toml``), then the
    hard cases into the same folder, then the report."""
    if args.reports is None:
        args.reports = str(Path(args.out) / "report")
    check_compare_out(args.out, args.overwrite)
    load_expected()  # its hard verdicts and claims: a damaged file is named before any work
    config = configured(**compare_fields(args), command=command_line(args))
    save_config(config, args)
    if args.readme is not None:
        try:
            check_readme(args.readme)
        except ValueError as error:
            raise InputError(str(error)) from None
    start = time.perf_counter()
    status = run_config(config, compare=True, quiet=args.quiet)
    if config is None:
        return status
    args.case = None
    runs_hard = {**compare_settings(dim=args.dim), **args.file_fields}.get("hard-cases", False)
    hard_status = hard_command(args, compare=True) if runs_hard else 0
    table = read_results(args.out)
    readme = write_report(table, args.reports, args.out)
    if args.readme is not None:
        write_compare_block(args.readme, args.out, time.perf_counter() - start)
        print(f"wrote the compare figures into {args.readme}")
    print_summary(readme, table, args.out, time.perf_counter() - start)
    return status or hard_status


def print_summary(readme: Path, table: pd.DataFrame, results, seconds: float | None) -> None:
    """The console's last lines (``bench.report.console``)."""
    hard_csv = Path(results) / "hard.csv"
    hard = pd.read_csv(hard_csv) if hard_csv.exists() else None
    truth = read_json(Path(results), "truth.json")
    print("\n" + "\n".join(console_summary(readme, table, hard, seconds, truth, Path(results))))


def report_command(args) -> int:
    table = read_results(args.results)
    if table is None:
        print(f"error: --results={args.results!r} holds no results.parquet", file=sys.stderr)
        return 2
    start = time.perf_counter()
    readme = write_report(table, args.out, args.results)
    print_summary(readme, table, args.results, time.perf_counter() - start)
    return 0


def export_command(args) -> int:
    if args.out is None:
        args.out = str(Path(args.results) / "fields")
    check_output_folder(args.out, "out")
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


COMMANDS = {"run": run_command, "compare": compare_command, "report": report_command,
            "export": export_command,
            "verify": verify_command, "hard": hard_command, "scaling": scaling_command,
            "list": list_command, "study": study_command,
            "diff": diff_command, "history": history_command}


def main(argv: list[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    load_plugins()  # before the parser too: its lists include the plugins' units
    try:  # before the parser: its lists of valid scenes include the files' scenes
        load_scene_files(scene_files_in(argv))  # a file that fails is named and left out
    except ValueError as error:  # a path that is not a scene file
        print(f"error: {error}", file=sys.stderr)
        return 2
    try:
        defaults = run_file_defaults(argv)
    except ValueError as error:  # a run file that cannot be read, an unknown key
        print(f"error: {error}", file=sys.stderr)
        return 2
    args = build_parser(defaults).parse_args(with_negative_values(argv))
    args.argv = argv
    args.file_fields = defaults.get(args.command, {})
    try:
        with ending_signals():
            check_output_folders(args.command, args)
            return COMMANDS[args.command](args)
    except (InputError, ResultsError, RunRefused, ExpectedError) as error:
        print(f"error: {error}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # the reader went away (e.g. `| head`): stop quietly
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 1
    except OSError as error:
        if error.errno not in FULL:
            raise
        print(f"error: {full_disk(error)}", file=sys.stderr)
        return 2
    except KeyboardInterrupt as error:
        print(ended_line(error, getattr(args, "out", "the output")), file=sys.stderr)
        return exit_status(error)


"""Running a configured matrix from the command line: the run's configuration (refused in one
line), its progress (``bench.cli.progress``), the timing of the cheapest again, and what
``run`` and ``compare`` print after it (docs/command-line.md, "What a run prints")."""

from __future__ import annotations

import sys

from bench.cli.guards import InputError
from bench.cli.progress import Progress, progress, summary
from bench.matrix import RunConfig, run
from bench.matrix.config_files import RunFileError, save_run_file


def configured(**fields) -> RunConfig | None:
    """The run's configuration, or None after printing why it is refused."""
    try:
        return RunConfig(**fields)
    except ValueError as error:
        print(f"error: {error}", file=sys.stderr)
        return None


def run_config(config: RunConfig | None, compare: bool = False, quiet: bool = False) -> int:
    """Run ``config``: a progress bar on a terminal; ``run`` prints a line per level and a
    table per sequence, ``compare`` (``compare``) only its progress (and nothing with
    ``quiet``), then prints its own summary."""
    if config is None:
        return 2
    live = Progress(len(config.specs()), quiet=quiet, what="matrix")
    timing: list[Progress] = []

    def timed(spec, total: int) -> None:  # the candidates to be the cheapest, timed again
        if not timing:
            live.close()
            timing.append(Progress(total, quiet=quiet, what="timing the cheapest again",
                                   lines=3))
        timing[0].sequence(spec)

    try:
        result = run(config, on_level=live.level(lambda r: None if compare else progress(r)),
                     on_sequence=live.sequence, on_timed=timed)
    finally:
        for bar in [live, *timing]:
            bar.close()
    say = (lambda *a: None) if quiet else print
    if result.reused:
        say(f"reused {len(result.reused)} sequences finished by an earlier run in "
            f"{result.store.out}")
    if not compare:
        print(f"wrote {result.store.out / 'rates.md'}")
        print("\n" + summary(result.table) + "\n")
    say(f"wrote {len(result.rows)} rows to {result.store.parquet} and {result.store.csv}")
    return 1 if result.failed else 0


def command_line(args) -> str:
    return " ".join(["python -m bench", *args.argv])


def save_config(config: RunConfig | None, args) -> None:
    """``--save-config FILE``: the run's full configuration as a run file."""
    if config is not None and getattr(args, "save_config", None):
        try:
            written = save_run_file(config, args.save_config, command_line(args))
        except RunFileError as error:
            raise InputError(str(error)) from None
        print(f"wrote {written}")

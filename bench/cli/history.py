"""``python -m bench history``: the suite's figures across commits (bench.history,
docs/history.md). ``record`` adds a commit's figures from results folders, ``check`` prints
what moved beyond its noise since the previous entry, ``page`` renders the static page."""

from __future__ import annotations

import datetime
import subprocess

from bench.cli.guards import InputError
from bench.history import (
    HISTORY_FILE,
    SOURCES,
    Figure,
    append_figures,
    figures_of,
    moves,
    read_history,
    write_page,
)
from bench.history.readme_source import headline, readme_commits


def add_history_parser(sub) -> None:
    history = sub.add_parser(
        "history", help="record, check and render the suite's figures across commits",
        description="The figures of verify, scaling and the default comparison, one entry per "
        "commit in a CSV file kept in the repository (docs/history.md).")
    history.add_argument("action", choices=["record", "check", "page", "backfill"],
                         help="record: add the figures of the results folders given as "
                              "SOURCE=FOLDER; check: print every figure of the last commit "
                              "that moved beyond its noise band (exit 1 with --strict); "
                              "page: write OUT/index.html; backfill: record the comparison's "
                              "headline of the last --commits commits that changed README.md "
                              "from their compare blocks")
    history.add_argument("folders", nargs="*", metavar="SOURCE=FOLDER",
                         help=f"(record) a source ({', '.join(SOURCES.names())}) and the "
                              "results folder of its command")
    history.add_argument("--file", default=str(HISTORY_FILE),
                         help=f"the history file (default: {HISTORY_FILE})")
    history.add_argument("--commit", default=None,
                         help="(record) the commit the figures belong to (default: HEAD)")
    history.add_argument("--out", default="results-history",
                         help="(page) the folder of the page (default: results-history)")
    history.add_argument("--strict", action="store_true",
                         help="(check) exit 1 when a figure moved")
    history.add_argument("--commits", type=int, default=10,
                         help="(backfill) how many commits (default: 10)")


def head_commit() -> str:
    try:
        return subprocess.run(["git", "rev-parse", "--short=12", "HEAD"], check=True,
                              capture_output=True, text=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        raise InputError("--commit is needed outside a git checkout") from None


def parse_folders(folders: list[str]) -> list[tuple[str, str]]:
    out = []
    for item in folders:
        source, sep, folder = item.partition("=")
        if not sep or source not in SOURCES.names():
            raise InputError(f"folders={item!r} is not SOURCE=FOLDER with SOURCE one of "
                             f"{', '.join(SOURCES.names())}")
        out.append((source, folder))
    return out


def history_command(args) -> int:
    if args.action == "record":
        pairs = parse_folders(args.folders)
        if not pairs:
            raise InputError("record needs at least one SOURCE=FOLDER")
        commit = args.commit or head_commit()
        stamp = datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds")
        try:
            figures = [f for source, folder in pairs
                       for f in figures_of(source, folder, commit, stamp)]
        except ValueError as error:
            raise InputError(str(error)) from None
        frame = append_figures(figures, args.file)
        print(f"recorded {len(figures)} figures of {commit} in {args.file} "
              f"({frame['commit'].nunique()} commits)")
        return check(args)
    if args.action == "check":
        return check(args)
    if args.action == "backfill":
        return backfill(args)
    page = write_page(read_history(args.file), args.out)
    print(f"wrote {page}")
    return 0


def check(args) -> int:
    found = moves(read_history(args.file))
    moved = [m for m in found if m.moved]
    for move in moved:
        print(f"moved: {move.line()}")
    print(f"{len(found)} figures against their previous entry; {len(moved)} moved beyond "
          "their noise band")
    return 1 if moved and getattr(args, "strict", False) else 0


def backfill(args) -> int:
    """The comparison's headline of earlier commits, from their README's compare block."""
    figures = []
    for commit, date, text in readme_commits(args.commits):
        figures += [Figure(commit, date, "compare", name, value, kind, noise)
                    for name, value, kind, noise in headline(text)]
    frame = append_figures(figures, args.file)
    print(f"recorded {len(figures)} figures of {frame['commit'].nunique()} commits in "
          f"{args.file}")
    return check(args)

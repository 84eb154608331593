"""``python -m bench diff OLD NEW``: did a change move the numbers? (bench.matrix.diff)"""

from __future__ import annotations

import bench.cli.option_types as options
from bench.cli.guards import InputError
from bench.matrix.diff import diff_results


def add_diff_parser(sub) -> None:
    diff = sub.add_parser(
        "diff", help="compare two results folders sequence by sequence (energy, eta, errors)",
        description="For every sequence in both folders: the largest relative difference of "
        "energy, contact force, eta, eta_0, the errors and the effectivity on the levels whose "
        "meshes agree (same DOFs and elements), and the level from which the meshes differ. "
        "Exits 1 when a difference on agreeing meshes exceeds --rtol.")
    diff.add_argument("old", help="results folder before the change")
    diff.add_argument("new", help="results folder after the change")
    diff.add_argument("--rtol", type=options.positive_float("rtol"), default=1e-10,
                      help="largest relative difference accepted (default: 1e-10)")


def diff_command(args) -> int:
    table = diff_results(args.old, args.new)
    compared = table[table["levels"] > 0]
    if compared.empty:
        only_old = int((table["worst_column"] == "only in old").sum())
        raise InputError(f"{args.old!r} and {args.new!r} have no sequence in common ({only_old} "
                         f"only in the first, {len(table) - only_old} only in the second); "
                         "nothing to compare: give two runs of the same settings")
    over = compared[compared["max_relative_difference"] > args.rtol]
    parted = compared[compared["mesh_differs_from_level"] >= 0]
    with_columns = table.assign(max_relative_difference=table["max_relative_difference"].map(
        "{:.1e}".format))
    print(with_columns.to_markdown(index=False))
    print(f"\n{len(compared)} sequences compared on {int(compared['levels'].sum())} levels; "
          f"largest relative difference on agreeing meshes "
          f"{compared['max_relative_difference'].max():.1e} (rtol {args.rtol:g}); "
          f"{len(parted)} sequences whose meshes differ from some level; "
          f"{len(table) - len(compared)} in one folder only")
    return 1 if len(over) else 0

"""``python -m bench scaling``: its options (the command is in ``bench.cli.commands``)."""

from __future__ import annotations

from bench.cli.option_types import (
    cell_list,
    name_list,
    order_list,
    positive_int,
    sequence_budgets,
)
from bench.perf.scaling import SIZES
from bench.perf.scaling_3d import SIZES_3D
from bench.perf.sequence import SEQUENCES
from formulations.cells import DEFAULT_CELL, cell_names
from formulations.solvers.backends import backend_names
from formulations.solvers.stopping import STOPPING_RULES


def add_scaling_parser(sub) -> None:
    scaling = sub.add_parser(
        "scaling", help="time assembly, linear solve, fast and reference contact solves and "
        "the estimator against N, with peak memory",
        description="Measure every phase once per size, each size in a fresh process, and "
        "write OUT/scaling.{md,csv} (and the table of a Markdown page with --readme).")
    scaling.add_argument("--sizes", type=name_list("size", sorted(set(SIZES) | set(SIZES_3D))),
                         default=None, help=f"sizes, comma-separated: {', '.join(SIZES)}; with "
                         f"--dim 3: {', '.join(SIZES_3D)} (default: all of the dimension's)")
    scaling.add_argument("--dim", type=int, choices=(2, 3), default=2,
                         help="2 (default): the paper scene, mixed; 3: paper-3d, vi, on "
                              "tetrahedra (OUT/scaling-3d.{md,csv})")
    scaling.add_argument("--backend", choices=backend_names(), default=None,
                         help="sparse back-end (default: the first available of "
                              + ", ".join(backend_names()) + ")")
    scaling.add_argument("--order", type=order_list, default=[1],
                         help="polynomial order(s) of the displacements (default: 1)")
    scaling.add_argument("--reference-max-dofs", type=positive_int("reference_max_dofs"),
                         default=200_000, help="run the reference solver only up to this "
                         "many DOFs (default: 200000)")
    scaling.add_argument("--out", default="reports", help="output folder (default: reports)")
    scaling.add_argument("--readme", default=None,
                         help="also replace the table between the scaling markers of this "
                              "Markdown file (e.g. docs/solvers.md; docs/three-d.md with --dim 3)")
    scaling.add_argument("--sequence", action="store_true",
                         help="time whole sequences instead (an adaptive one and a uniform one, "
                              "every level and phase) against one linear solve at the finest "
                              "level; writes OUT/scaling-sequence.{md,csv}")
    scaling.add_argument("--cell", type=cell_list, default=[DEFAULT_CELL],
                         help="with --sequence: the cell shape(s) of the sequences, "
                              f"comma-separated, from {', '.join(cell_names())} (default: "
                              f"{DEFAULT_CELL})")
    scaling.add_argument("--stopping", type=name_list("stopping", STOPPING_RULES.names()),
                         default=["fixed"],
                         help="with --sequence: the stopping rule(s) of the solvers, "
                              f"comma-separated, from {', '.join(STOPPING_RULES.names())} "
                              "(docs/theory.md, 18; default: fixed)")
    scaling.add_argument("--sequence-strategies", type=name_list("strategy", ["adaptive",
                                                                             "uniform"]),
                         default=["adaptive", "uniform"],
                         help="with --sequence: which of the two sequences run (default: "
                              "adaptive,uniform)")
    scaling.add_argument("--sequence-max-dofs", type=sequence_budgets,
                         default=[b for _, b in SEQUENCES],
                         help="the DOF budgets of the adaptive and the uniform sequence, "
                              "comma-separated (default: "
                              + ",".join(str(b) for _, b in SEQUENCES) + ")")

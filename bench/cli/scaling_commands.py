"""``python -m bench scaling``: the scaling table (2D, 3D) and the sequence benchmark."""

from __future__ import annotations

from bench.cli.guards import InputError
from bench.perf import scaling, scaling_3d, sequence
from bench.perf.scaling import SIZES, check_markers, run_scaling, write_scaling
from bench.perf.scaling_3d import SIZES_3D, run_scaling_3d, write_scaling_3d
from bench.perf.sequence import SEQUENCES, run_sequences, write_sequences
from formulations.solvers.backends import check_backend

SCALING_MARKERS = (scaling.README_START, scaling.README_END)
SCALING_3D_MARKERS = (scaling_3d.README_START_3D, scaling_3d.README_END_3D)
SEQUENCE_MARKERS = (sequence.README_START, sequence.README_END)


def show(row) -> None:
    print(f"{row['size']} P{row['order']}: ndofs {row['ndofs']}  "
          f"fast {row['t_fast_solve']:.2f} s  "
          f"linear {row['t_linear_solve']:.2f} s  reference "
          f"{row['t_reference_solve']:.2f} s  peak {row['peak_gib']:.2f} GiB", flush=True)


def show_3d(row) -> None:
    print(f"{row['size']} P{row['order']} 3D: ndofs {row['ndofs']}  assembly "
          f"{row['t_assemble']:.2f} s  linear {row['t_linear_solve']:.2f} s  fast "
          f"{row['t_fast_solve']:.2f} s  peak {row['peak_gib']:.2f} GiB", flush=True)


def scaling_2d(args, sizes: list[str]) -> str:
    frame = run_scaling(sizes, args.backend, args.reference_max_dofs, on_row=show,
                        orders=args.order)
    return write_scaling(frame, args.out, args.readme)


def scaling_3d_table(args, sizes: list[str]) -> str:
    frame = run_scaling_3d(sizes, args.backend, args.order, on_row=show_3d)
    return write_scaling_3d(frame, args.out, args.readme)


# per dimension: the README block the scaling table goes into, its sizes and its run
SCALING_BY_DIM = {2: (SCALING_MARKERS, SIZES, scaling_2d),
                  3: (SCALING_3D_MARKERS, SIZES_3D, scaling_3d_table)}


def scaling_command(args) -> int:
    try:
        check_backend(args.backend)
    except ValueError as error:
        raise InputError(f"--backend: {error}") from None
    if args.readme is not None:  # before anything is measured
        start, end = SEQUENCE_MARKERS if args.sequence else SCALING_BY_DIM[args.dim][0]
        try:
            check_markers(args.readme, start, end)
        except ValueError as error:
            raise InputError(f"--{error}") from None
    if args.sequence:
        return sequence_command(args)
    allowed = SCALING_BY_DIM[args.dim][1]
    sizes = args.sizes or list(allowed)
    wrong = [size for size in sizes if size not in allowed]
    if wrong:
        raise InputError(f"--sizes={','.join(wrong)} is not one of {', '.join(allowed)} "
                         f"in {args.dim}D")
    print(f"wrote {SCALING_BY_DIM[args.dim][2](args, sizes)}")
    return 0


def sequence_command(args) -> int:
    def show(row):
        print(f"{row['strategy']} to {row['max_dofs']} ({row['cell']}, {row['stopping']} "
              f"stopping): {row['levels']} levels, "
              f"finest "
              f"{row['final_ndofs']} DOFs, {row['t_sequence']:.1f} s = "
              f"{row['sequence_over_linear']:.1f} linear solves at the finest level", flush=True)
    budgets = [(strategy, budget) for strategy, budget in zip(
        [s for s, _ in SEQUENCES], args.sequence_max_dofs, strict=True)
        if strategy in args.sequence_strategies]
    frame = run_sequences(budgets, args.backend, on_row=show, cells=args.cell,
                          stopping=args.stopping)
    print(f"wrote {write_sequences(frame, args.out, args.readme)}")
    return 0

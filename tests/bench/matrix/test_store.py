"""The store's units: a rerun of a sequence cut short keeps the earlier attempt's levels until
it passes them; temporary files of ended writers are found; the overwrite's set-aside folder
is put back (docs/reliability.md, "The store")."""

import os
import subprocess
import sys

import pandas as pd

from bench.matrix.files import abandoned_temporaries, atomic_path
from bench.matrix.store import SequenceWriter
from bench.sequence.rows import COLUMNS, INTERRUPTED, ResultRow


def row(level: int, run_id: str) -> ResultRow:
    return ResultRow(scene="paper", formulation="mixed", solver="active-set",
                     estimator="residual", strategy="adaptive", level=level, run_id=run_id,
                     sequence_key="k")


def cut_short(path, levels: int) -> None:
    writer = SequenceWriter(path)
    for level in range(levels):
        writer.append(row(level, "first"))
    writer.finish(INTERRUPTED)


def levels_by_run(path) -> list[tuple[int, str]]:
    frame = pd.read_parquet(path)
    return list(zip(frame["level"], frame["run_id"], strict=True))


def test_a_rerun_cut_shorter_keeps_the_earlier_attempts_levels(tmp_path):
    path = tmp_path / "k.parquet"
    cut_short(path, 5)
    rerun = SequenceWriter(path)
    rerun.append(row(0, "second"))
    rerun.append(row(1, "second"))
    assert levels_by_run(path) == [(0, "second"), (1, "second"), (2, "first"), (3, "first"),
                                   (4, "first")]
    rerun.finish(INTERRUPTED)  # cut short again: the earlier levels stay
    assert len(pd.read_parquet(path)) == 5


def test_a_rerun_that_finishes_holds_only_its_own_rows(tmp_path):
    path = tmp_path / "k.parquet"
    cut_short(path, 5)
    rerun = SequenceWriter(path)
    for level in range(3):
        rerun.append(row(level, "second"))
    rerun.finish("budget")  # its own end: a level it did not reach is not the sequence's
    frame = pd.read_parquet(path)
    assert levels_by_run(path) == [(0, "second"), (1, "second"), (2, "second")]
    assert set(frame["sequence_end"]) == {"budget"} and list(frame.columns) == COLUMNS


def test_a_finished_partition_is_not_carried(tmp_path):
    path = tmp_path / "k.parquet"
    writer = SequenceWriter(path)
    writer.append(row(0, "first"))
    writer.finish("budget")
    assert SequenceWriter(path).carried == []


def test_temporary_files_of_ended_writers_are_found_and_live_ones_kept(tmp_path):
    ended = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                           capture_output=True, text=True, check=True)
    with atomic_path(tmp_path / "live.parquet") as tmp:
        tmp.write_bytes(b"half")
        dead = tmp.with_name(tmp.name.replace(f"~{os.getpid()}.", f"~{ended.stdout.strip()}."))
        dead.write_bytes(b"half")
        assert abandoned_temporaries(tmp_path) == [dead]  # this process's own is alive
    assert (tmp_path / "live.parquet").read_bytes() == b"half"

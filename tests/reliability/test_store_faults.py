"""The store has one record, the partitions: commands that only read write nothing into a
results folder and keep, with a count, rows that only the tables or a set-aside folder hold;
the next run writes them back; every signal that ends a run keeps its finished rows and puts
back what an --overwrite run set aside (docs/reliability.md, "The store", "Signals")."""

import errno
import fcntl
import os
import signal
import time

import pandas as pd
import pytest

import bench.matrix.files as files_module
from bench.cli import main
from bench.matrix.folder_state import OWNER, FolderState
from bench.matrix.store import read_results
from conftest import folder_bytes, interruptible_bench

FAST = ["--scene", "free-boundary", "--formulation", "vi,mixed", "--solver", "active-set",
        "--max-dofs", "300"]


def row_keys(table: pd.DataFrame) -> set:
    return set(zip(table["sequence_key"], table["level"], table["run_id"], strict=True))


def test_a_missing_partition_is_kept_by_readers_and_written_back_by_the_next_run(
        results_copy, tmp_path, capsys):
    table = pd.read_parquet(results_copy / "results.parquet")
    partition = sorted((results_copy / "sequences").glob("*.parquet"))[0]
    lost = len(pd.read_parquet(partition))
    partition.unlink()
    before = folder_bytes(results_copy)
    assert main(["report", "--results", str(results_copy), "--out", str(tmp_path / "r")]) == 0
    assert main(["diff", str(results_copy), str(results_copy)]) == 0
    err = capsys.readouterr().err
    assert f"holds {lost} rows of 1 sequence" in err and "they are kept" in err
    assert f"{len(table)} result rows" in (tmp_path / "r" / "README.md").read_text()
    assert folder_bytes(results_copy) == before  # neither reader wrote a byte
    assert row_keys(read_results(results_copy)) == row_keys(table)
    assert main(["run", *FAST, "--out", str(results_copy)]) == 0
    assert "written back" in capsys.readouterr().err
    assert len(pd.read_parquet(partition)) == lost
    assert row_keys(pd.read_parquet(results_copy / "results.parquet")) == row_keys(table)


def dead_set_aside(folder, stem: str):
    """What a killed --overwrite run leaves: the earlier results in .previous-*, an owner
    file that no process holds."""
    aside = folder / ".previous-1-1"
    (aside / "sequences").mkdir(parents=True)
    (aside / OWNER).write_text("1")
    for name in ("results.parquet", "results.csv"):
        os.replace(folder / name, aside / name)
    os.replace(folder / "sequences" / f"{stem}.parquet", aside / "sequences" / f"{stem}.parquet")
    return aside


def test_a_killed_overwrite_leaves_nothing_hidden(results_copy, tmp_path, capsys):
    table = pd.read_parquet(results_copy / "results.parquet")
    stem = sorted((results_copy / "sequences").glob("*.parquet"))[0].stem
    aside = dead_set_aside(results_copy, stem)
    assert row_keys(read_results(results_copy)) == row_keys(table)
    assert "that an --overwrite run set aside" in capsys.readouterr().err
    assert main(["run", *FAST, "--out", str(results_copy)]) == 0
    assert "they are put back" in capsys.readouterr().err
    assert not aside.exists() and not list(results_copy.glob(".discard-*"))
    assert row_keys(pd.read_parquet(results_copy / "results.parquet")) == row_keys(table)


def test_a_set_aside_folder_whose_run_still_runs_is_left_alone(results_copy, capsys):
    stem = sorted((results_copy / "sequences").glob("*.parquet"))[0].stem
    aside = dead_set_aside(results_copy, stem)
    handle = os.open(aside / OWNER, os.O_RDWR)
    fcntl.flock(handle, fcntl.LOCK_EX)  # as its run holds it while it runs
    try:
        state = FolderState.read(results_copy)
        assert [a.alive for a in state.set_aside] == [True]
        assert "set aside" not in capsys.readouterr().err
    finally:
        os.close(handle)
    assert [a.alive for a in FolderState.read(results_copy).set_aside] == [False]


@pytest.mark.parametrize("ending", [signal.SIGTERM, signal.SIGHUP, signal.SIGINT])
def test_every_ending_signal_puts_back_what_an_overwrite_set_aside(results_copy, ending):
    table = pd.read_parquet(results_copy / "results.parquet")
    process = interruptible_bench("run", "--scene", "paper", "--max-dofs", "2000000",
                                  "--strategy", "uniform", "--solver", "reference",
                                  "--overwrite", "--out", str(results_copy))
    deadline = time.time() + 120
    while time.time() < deadline and not list(results_copy.glob(".previous-*")):
        time.sleep(0.05)  # the earlier results are set aside: the run has started
    time.sleep(0.5)
    process.send_signal(ending)
    _, err = process.communicate(timeout=120)
    assert process.returncode == 128 + ending, err
    lines = [line for line in err.splitlines() if not line.startswith("note: ")]  # notes aside
    assert len(lines) == 1 and "every finished row is kept" in lines[0], err
    assert not list(results_copy.glob(".previous-*"))
    after = read_results(results_copy)
    assert row_keys(table) <= row_keys(after)
    assert after[["sequence_key", "level"]].duplicated().sum() == 0


def test_a_full_disk_is_one_line_and_leaves_nothing_half_written(results_copy, monkeypatch,
                                                                  capsys):
    before = read_results(results_copy)
    real_write = files_module.atomic_bytes

    def full_after_first(data, path, calls=[]):  # noqa: B006 - counts the writes of one run
        calls.append(path)
        if len(calls) > 1:
            with files_module.atomic_path(path, len(data)) as tmp:
                with open(tmp, "wb") as handle:
                    handle.write(data[: len(data) // 2])
                raise OSError(errno.ENOSPC, "No space left on device")
        real_write(data, path)

    monkeypatch.setattr(files_module, "atomic_bytes", full_after_first)
    status = main(["run", "--scene", "paper", "--max-dofs", "300", "--out", str(results_copy)])
    err = capsys.readouterr().err
    assert status == 2 and "Traceback" not in err
    line = [x for x in err.splitlines() if x.startswith("error:")]
    assert len(line) == 1 and "no space left on the device of" in line[0]
    assert "needed" in line[0] and str(results_copy) in line[0]
    assert not [p for p in results_copy.rglob("*.tmp")]
    monkeypatch.undo()
    assert row_keys(before) <= row_keys(read_results(results_copy))

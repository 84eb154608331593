"""Fault injection (docs/reliability.md, "How it is tested"): runs of each kind (plain,
--overwrite, --workers 2, a resumed run) are ended by SIGTERM, SIGKILL or SIGHUP at random
moments, and runs are given a disk that fills at a random point. After each fault the next
command must see every row that was finished before it, no row twice, and no partial state:
no hidden set-aside folder, no half-written file. TRIALS per kind (50, as documented; set
SIGNORINI_FAULT_TRIALS to change it)."""

from __future__ import annotations

import os
import random
import shutil
import signal
import subprocess
import time
from pathlib import Path

import pandas as pd
import pytest
from fault_runs import start

from bench.matrix.folder_state import FINISHED, FolderState
from bench.matrix.store import ResultStore, read_results

pytestmark = pytest.mark.slow

TRIALS = int(os.environ.get("SIGNORINI_FAULT_TRIALS", "50"))
DISK_TRIALS = int(os.environ.get("SIGNORINI_FAULT_DISK_TRIALS", "20"))
SIGNALS = (signal.SIGTERM, signal.SIGKILL, signal.SIGHUP)
COMMAND = ["run", "--scene", "free-boundary,paper", "--formulation", "vi,mixed,penalty",
           "--solver", "active-set", "--max-dofs", "1500"]
KINDS = {"plain": [], "overwrite": ["--overwrite"], "workers": ["--workers", "2"]}
LATEST = {"plain": 3.5, "overwrite": 3.5, "workers": 7.0, "resume": 3.5}  # seconds: a run's end


def rows_of(table: pd.DataFrame | None) -> set:
    """(sequence, level) of every row: a level recomputed by the rerun of a sequence cut short
    replaces the earlier attempt's row of that level (the same result, another run id)."""
    if table is None or not len(table):
        return set()
    return set(zip(table["sequence_key"], table["level"], strict=True))


def runs_of(table: pd.DataFrame) -> set:
    return set(table["run_id"])


def check_after(folder: Path, before: set, earlier: set, earlier_runs: set, status: int,
                err: str) -> pd.DataFrame:
    """What the next command must see after a fault (module docstring)."""
    assert "Traceback" not in err, err
    assert status in (0, 1, -signal.SIGKILL, 128 + signal.SIGTERM, 128 + signal.SIGHUP), err
    if status > 128:
        ending = [line for line in err.splitlines() if line.startswith("interrupted:")]
        assert len(ending) == 1, err
    after = read_results(folder)
    seen = rows_of(after)
    new = after[~after["run_id"].isin(earlier_runs)]
    committed = new["sequence_end"].isin(FINISHED).any()  # an --overwrite may delete now
    assert before - (earlier if committed else set()) <= seen
    assert not after[["sequence_key", "level"]].duplicated().any()
    ResultStore(folder)  # the next writer: whatever was set aside comes back or goes
    assert not list(folder.glob(".previous-*")) and not list(folder.glob(".discard-*"))
    assert rows_of(FolderState.read(folder).record()) >= before - (
        earlier if committed else set())
    assert not list(folder.rglob("*.tmp"))
    return after


def one_fault(kind: str, folder: Path, logs: Path, rng: random.Random,
              earlier: tuple[set, set]) -> dict:
    """Start a run of ``kind`` into ``folder``, end it at a random moment, check the folder."""
    extra = KINDS.get(kind, [])
    command = start([*COMMAND, *extra, "--out", str(folder)], logs)
    number = rng.choice(SIGNALS)
    deadline = command.started + rng.uniform(0.2, LATEST[kind])
    while time.monotonic() < deadline and command.process.is_alive():
        time.sleep(0.02)
    before = rows_of(FolderState.read(folder, shared=True).rows())  # read just before the signal
    command.signal(number)
    status = command.wait()
    _, err = command.output()
    after = check_after(folder, before, *earlier, status, err)
    failed = after[(after["status"] == "failed") & ~after["run_id"].isin(earlier[1])]
    reasons = sorted(set(failed["reason"].astype(str)))
    assert not [r for r in reasons if "Interrupt" in r or "Ended" in r], reasons
    return {"kind": kind, "signal": signal.Signals(number).name, "status": status,
            "rows_before": len(before), "rows_after": len(after),
            "failed": "; ".join(reasons)[:300]}


@pytest.mark.parametrize("kind", [*KINDS, "resume"])
def test_runs_ended_at_random_moments_lose_nothing(finished_run, tmp_path, kind):
    rng = random.Random(f"faults-{kind}")
    logs = tmp_path / "logs"
    logs.mkdir()
    seed = pd.read_parquet(finished_run / "results.parquet")
    seeded = (rows_of(seed), runs_of(seed))
    outcomes, completed = [], 0
    folder = None
    for trial in range(TRIALS):
        if kind != "resume" or folder is None:
            folder = tmp_path / f"r{trial}"
            shutil.copytree(finished_run, folder)
        earlier = seeded if kind == "overwrite" else (set(), set())
        outcomes.append(one_fault(kind, folder, logs, rng, earlier))
        if kind == "resume" and outcomes[-1]["status"] in (0, 1):  # the chain ran to its end
            check_complete(folder)
            completed += 1
            folder = None
        elif kind != "resume":
            shutil.rmtree(folder)
    summary = pd.DataFrame(outcomes)
    failed = summary[summary["failed"] != ""]
    print(f"\n{kind}: {len(summary)} faults, by signal and exit status:\n"
          + summary.groupby(["signal", "status"]).size().to_string()
          + "".join(f"\nfailed rows after {r.signal} (exit {r.status}): {r.failed}"
                    for r in failed.itertuples())
          + (f"\n{completed} resumed chains completed" if kind == "resume" else ""))
    assert len(summary) == TRIALS


def check_complete(folder: Path) -> None:
    """A resumed run that reached its end holds every sequence of its command once, finished
    (a sequence cut short earlier was rerun, its partial rows replaced)."""
    table = read_results(folder)
    mine = table[table["scene"].isin(["free-boundary", "paper"])]
    ends = mine.groupby("sequence_key")["sequence_end"].agg(lambda s: set(s))
    assert all(e <= set(FINISHED) for e in ends), ends
    assert not mine[["sequence_key", "level"]].duplicated().any()


def mount_small(folder: Path, kilobytes: int) -> bool:
    folder.mkdir(parents=True, exist_ok=True)
    done = subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={kilobytes}k", "tmpfs",
                           str(folder)], capture_output=True)
    return done.returncode == 0


def test_a_disk_that_fills_at_a_random_point_loses_nothing(tmp_path, capsys):
    rng = random.Random("disk")
    if not mount_small(tmp_path / "probe", 64):
        pytest.skip("mounting a small tmpfs needs root (CAP_SYS_ADMIN) on this machine")
    subprocess.run(["umount", str(tmp_path / "probe")], check=True)
    full = 0
    for trial in range(DISK_TRIALS):
        disk, logs = tmp_path / f"disk{trial}", tmp_path / f"logs{trial}"
        logs.mkdir()
        assert mount_small(disk, rng.randint(120, 1600))
        try:
            command = start([*COMMAND, "--out", str(disk / "r")], logs)
            status = command.wait()
            out, err = command.output()
            full += check_full_disk(disk / "r", status, out, err)
        finally:
            subprocess.run(["umount", str(disk)], check=True)
    print(f"\n{DISK_TRIALS} runs on a small disk, {full} of them filled it")
    assert full >= DISK_TRIALS // 2  # the sizes are drawn so that most runs fill the disk


def check_full_disk(folder: Path, status: int, out: str, err: str) -> bool:
    """Whether the disk filled; if so: one line, nothing half-written, every row the run
    printed as finished is readable."""
    assert "Traceback" not in err, err
    if status == 0:
        return False
    lines = [line for line in err.splitlines() if line.startswith("error:")]
    assert status == 2 and len(lines) == 1 and "no space left on the device" in lines[0], err
    assert not list(folder.rglob("*.tmp"))
    printed = {(line.split()[0], int(line.split()[2])) for line in out.splitlines()
               if " level " in line and line.split()[1] == "level"}
    table = read_results(folder) if (folder / "sequences").exists() else None
    seen = set() if table is None else {
        ("/".join(map(str, r[:5])), int(r[5])) for r in table[
            ["scene", "formulation", "solver", "estimator", "strategy", "level"]].itertuples(
            index=False)}
    assert printed <= seen, printed - seen
    return True


def test_ctrl_c_with_dask_workers_is_one_line(tmp_path):
    folder = tmp_path / "r"
    command = start([*COMMAND, "--workers", "2", "--out", str(folder)], tmp_path)
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and not list(folder.glob("sequences/*.parquet")):
        time.sleep(0.05)  # the workers run: a sequence has written its first level
    command.signal(signal.SIGINT)  # to the process group, as a terminal's Ctrl-C
    status = command.wait()
    _, err = command.output()
    # notes (no reference for a scene, or the cached one taken) are not the interruption's
    lines = [line for line in err.splitlines() if not line.startswith("note: ")]
    assert status == 128 + signal.SIGINT and len(lines) == 1, err
    assert lines[0].startswith("interrupted: every finished row is kept")

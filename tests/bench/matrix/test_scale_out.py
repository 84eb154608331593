"""The store under concurrent writers and interrupts, resume, sweeps, and the matrix on Dask."""

import os
import shutil
import signal
import time

import numpy as np
import pandas as pd
import pytest

from bench.matrix import RunConfig, run
from bench.matrix.store import ResultStore
from bench.measure.contact import SOLVED_STATUSES as SOLVED
from bench.report.render import latest_run
from conftest import interruptible_bench

NUMBERS = ["ndofs", "energy", "contact_force", "eta", "energy_error", "effectivity_index"]
SMALL = dict(scenes=("free-boundary",), formulations=("mixed", "vi"), solvers=("active-set",),
             estimators=("residual",), strategies=("uniform", "adaptive"), max_dofs=2500)


@pytest.fixture(scope="module")
def small_run(tmp_path_factory):
    """(folder, result) of one in-process run of SMALL, for the tests to compare with or copy."""
    out = tmp_path_factory.mktemp("small")
    return out, run(RunConfig(**SMALL, out=str(out)))


def same_rows(a: pd.DataFrame, b: pd.DataFrame) -> None:
    keys = ["scene", "formulation", "solver", "estimator", "strategy", "scene_parameters",
            "formulation_options", "level"]
    a, b = (t.sort_values(keys).reset_index(drop=True) for t in (a, b))
    assert a[keys].equals(b[keys])
    # the Dask workers factorise with one thread, this process with the machine's: PARDISO's
    # parallel factorisation rounds differently (measured up to 1.7e-12 relative in eta at
    # 140 000 DOFs), so 1e-10, far below any effect of a lost or duplicated level
    for column in NUMBERS:
        np.testing.assert_allclose(a[column].astype(float), b[column].astype(float),
                                   rtol=1e-10, atol=0)


def test_two_runs_into_one_folder_at_once_lose_nothing(tmp_path):
    out = tmp_path / "shared"
    first = interruptible_bench("run", "--scene", "free-boundary", "--formulation", "mixed",
                                "--solver", "active-set", "--strategy", "uniform,adaptive",
                                "--max-dofs", "3000", "--out", str(out))
    second = interruptible_bench("run", "--scene", "free-boundary", "--formulation", "vi",
                                 "--solver", "active-set", "--strategy", "uniform,adaptive",
                                 "--max-dofs", "3000", "--out", str(out))
    for process in (first, second):
        _, err = process.communicate(timeout=300)
        assert process.returncode == 0, err
    table = pd.read_parquet(out / "results.parquet")
    csv = pd.read_csv(out / "results.csv")
    assert len(table) == len(csv) and set(table["formulation"]) == {"mixed", "vi"}
    assert not table.duplicated(["formulation", "strategy", "level"]).any()
    assert table["run_id"].nunique() == 2  # unique even when started in the same second
    assert set(table["sequence_end"]) <= {"budget", "max_levels"}


def test_a_rerun_reuses_finished_sequences_and_reruns_the_rest(small_run, tmp_path):
    out = shutil.copytree(small_run[0], tmp_path / "rerun")
    config, first = RunConfig(**SMALL, out=str(out)), small_run[1]
    assert len(first.rows) == len(first.table) and not first.reused
    store = ResultStore(out)
    # cut one sequence short, as a killed run leaves it: no end recorded, levels missing
    key = first.table["sequence_key"].iloc[0]
    part = store.partitions / f"{key}.parquet"
    cut = pd.read_parquet(part).iloc[:2].assign(sequence_end="")
    cut.to_parquet(part, index=False)
    second = run(config)
    assert set(second.reused) == set(first.table["sequence_key"]) - {key}
    assert {r.sequence_key for r in second.rows} == {key}
    same_rows(first.table, second.table)
    assert len(pd.read_parquet(out / "results.parquet")) == len(first.table)
    assert len(run(RunConfig(**SMALL, out=str(out), overwrite=True)).reused) == 0


def test_the_report_prefers_a_finished_sequence_over_a_cut_short_rerun(small_run):
    table = small_run[1].table
    short = table[table["level"] <= 1].assign(run_id="99999999T999999-ffffff",
                                              sequence_end="interrupted")
    shown = latest_run(pd.concat([table, short], ignore_index=True))
    same_rows(table, shown)


@pytest.mark.slow  # about 30 s: six sequences run until a signal ends the run, then resumed
def test_an_interrupted_run_is_resumed(tmp_path):
    out = tmp_path / "r"
    # six sequences: after the first two, four are left (seconds of work), so the interrupt
    # does not come after the whole run on an idle machine (with four, it once did)
    args = ["run", "--scene", "paper,free-boundary", "--formulation", "mixed,vi,penalty",
            "--solver", "active-set", "--strategy", "uniform", "--max-dofs", "140000", "--out",
            str(out)]
    process = interruptible_bench(*args)
    deadline = time.time() + 120
    while time.time() < deadline:  # until the first sequences have finished
        parts = list((out / "sequences").glob("*.parquet")) if out.exists() else []
        if len(parts) >= 2:
            break
        time.sleep(0.2)
    process.send_signal(signal.SIGINT)
    process.communicate(timeout=120)
    assert process.returncode == 130
    before = pd.read_parquet(out / "results.parquet")
    finished = set(before.loc[before["sequence_end"] == "budget", "sequence_key"])
    assert finished and "interrupted" in set(before["sequence_end"])
    again = interruptible_bench(*args)
    stdout, err = again.communicate(timeout=300)
    assert again.returncode == 0, err
    assert f"reused {len(finished)} sequences" in stdout
    after = pd.read_parquet(out / "results.parquet")
    assert len(after.groupby("sequence_key")) == 6 and set(after["sequence_end"]) == {"budget"}
    kept = after[after["sequence_key"].isin(finished)]
    assert set(kept["run_id"]) == set(before.loc[before["sequence_key"].isin(finished),
                                                 "run_id"])  # not recomputed


def test_a_sweep_of_poisson_ratios_gives_a_set_of_rows_each(tmp_path):
    table = run(RunConfig(scenes=("paper:poisson_ratio=0.3|0.45|0.49",), solvers=("active-set",),
                          max_dofs=600, out=str(tmp_path))).table
    assert sorted(set(table["scene_parameters"])) == [
        "poisson_ratio=0.3", "poisson_ratio=0.45", "poisson_ratio=0.49"]
    energies = table.groupby("scene_parameters")["energy"].last()
    assert energies.nunique() == 3 and table["status"].isin(SOLVED).all()
    truth = (tmp_path / "truth.json").read_text()
    assert "paper:poisson_ratio=0.45" in truth


def test_sweep_values_are_checked_by_name_and_by_value(tmp_path):
    with pytest.raises(ValueError, match="scene 'paper' has no parameter 'poisson'; its "
                                         "parameters: young_modulus, poisson_ratio"):
        run(RunConfig(scenes=("paper:poisson=0.3",), max_dofs=300, out=str(tmp_path)))
    with pytest.raises(ValueError, match="poisson_ratio=0.5 is not < 0.5"):
        run(RunConfig(scenes=("paper:poisson_ratio=0.5",), max_dofs=300, out=str(tmp_path)))
    with pytest.raises(ValueError, match="formulation 'mixed' has no parameter 'ratio'"):
        run(RunConfig(formulations=("mixed:ratio=1",), max_dofs=300, out=str(tmp_path)))


def test_two_dask_workers_give_the_rows_of_the_in_process_run(small_run, tmp_path):
    here = small_run[1].table
    dask = run(RunConfig(**SMALL, out=str(tmp_path / "dask"), workers=2)).table
    same_rows(here, dask)
    assert len(pd.read_parquet(tmp_path / "dask" / "results.parquet")) == len(here)


@pytest.mark.slow  # about 15 s: a Dask cluster whose worker is killed mid-run
def test_a_killed_worker_loses_and_duplicates_nothing(tmp_path):
    from dask.distributed import Client, LocalCluster

    cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                           dashboard_address=":0")
    client = Client(cluster)
    config = RunConfig(scenes=("paper",), formulations=("mixed", "vi"), solvers=("active-set",),
                       strategies=("uniform",), max_dofs=140000, out=str(tmp_path / "d"),
                       scheduler=cluster.scheduler_address)

    killed = []

    def kill_a_busy_worker():
        deadline = time.time() + 120
        while time.time() < deadline:
            busy = [w for w, tasks in client.processing().items() if tasks]
            parts = list((tmp_path / "d" / "sequences").glob("*.parquet"))
            if busy and parts:  # a task has written a level: kill its worker mid-sequence
                killed.append(busy[0])
                try:
                    client.run(lambda: os.kill(os.getpid(), signal.SIGKILL), workers=busy[:1])
                except Exception:  # the worker dies before it can answer
                    pass
                return
            time.sleep(0.1)
    import threading

    killer = threading.Thread(target=kill_a_busy_worker)
    killer.start()
    table = run(config).table
    killer.join()
    client.close()
    cluster.close()
    reference = run(RunConfig(scenes=("paper",), formulations=("mixed", "vi"),
                              solvers=("active-set",), strategies=("uniform",),
                              max_dofs=140000, out=str(tmp_path / "here"))).table
    assert killed  # the kill happened while a sequence was running
    same_rows(reference, table)
    assert not table.duplicated(["formulation", "level"]).any()

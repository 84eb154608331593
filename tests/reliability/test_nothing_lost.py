"""No command loses a finished result: a refused command leaves the folder byte for byte as it
was, --overwrite deletes the earlier results only once the new run has finished a sequence,
and compare never replaces a folder it did not write (README, "Reliability")."""

import json

import pandas as pd
import pytest

import bench.matrix.local as local_module
from bench.cli import main
from bench.matrix import RunConfig, run
from conftest import folder_bytes

FAST = ["--scene", "free-boundary", "--solver", "active-set", "--max-dofs", "300"]


@pytest.mark.parametrize("refused", [
    ["--formulation", "mixed:h_over_H=2"],  # an option value the formulation refuses
    ["--scheduler", "tcp://127.0.0.1:1"],  # no scheduler there
    ["--scene", "free-boundary:initial_divisions=40"],  # the starting mesh is over the budget
    ["--cache", "FILE"],  # a cache folder that is a file
])
def test_a_refused_overwrite_leaves_every_file_as_it_was(results_copy, tmp_path, capsys,
                                                         refused):
    before = folder_bytes(results_copy)
    (tmp_path / "FILE").write_text("")
    refused = [str(tmp_path / "FILE") if a == "FILE" else a for a in refused]
    assert main(["run", *FAST, *refused, "--overwrite", "--out", str(results_copy)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and "Traceback" not in err
    assert folder_bytes(results_copy) == before


def test_compare_refuses_a_folder_it_did_not_write(results_copy, capsys):
    before = folder_bytes(results_copy)
    assert main(["compare", "--out", str(results_copy)]) == 2
    err = capsys.readouterr().err
    assert "compare did not write" in err and "--overwrite" in err
    assert folder_bytes(results_copy) == before


def test_compare_with_a_dead_scheduler_keeps_its_own_folder(results_copy, capsys):
    record = json.loads((results_copy / "run.json").read_text())
    record["command"] = "python -m bench compare"  # as if compare had written it
    (results_copy / "run.json").write_text(json.dumps(record))
    before = folder_bytes(results_copy)
    assert main(["compare", "--scheduler", "tcp://127.0.0.1:1", "--out",
                 str(results_copy)]) == 2
    assert "no Dask scheduler answered" in capsys.readouterr().err
    assert folder_bytes(results_copy) == before


def test_an_overwrite_that_fails_before_a_sequence_finishes_brings_them_back(
        results_copy, monkeypatch):
    before = pd.read_parquet(results_copy / "results.parquet")

    def crash(*args, **kwargs):
        raise KeyboardInterrupt  # Ctrl-C during the first sequence

    monkeypatch.setattr(local_module, "run_spec", crash)
    with pytest.raises(KeyboardInterrupt):
        run(RunConfig(scenes=("paper",), solvers=("active-set",), max_dofs=300,
                      out=str(results_copy), overwrite=True))
    after = pd.read_parquet(results_copy / "results.parquet")
    assert set(after["sequence_key"]) >= set(before["sequence_key"])
    assert len(after) >= len(before)
    assert not list(results_copy.glob(".previous-*"))


def test_an_overwrite_deletes_the_earlier_results_once_it_has_finished(results_copy):
    old = set(pd.read_parquet(results_copy / "results.parquet")["sequence_key"])
    result = run(RunConfig(scenes=("paper",), solvers=("active-set",), max_dofs=300,
                           out=str(results_copy), overwrite=True))
    keys = set(pd.read_parquet(results_copy / "results.parquet")["sequence_key"])
    assert keys == {s.key for s in RunConfig(scenes=("paper",), solvers=("active-set",),
                                              max_dofs=300).specs()}
    assert not keys & old and len(result.rows) > 0
    assert not list(results_copy.glob(".previous-*"))


def test_two_runs_into_one_folder_are_both_described(results_copy):
    run(RunConfig(scenes=("paper",), solvers=("active-set",), max_dofs=300,
                  out=str(results_copy)))
    record = json.loads((results_copy / "run.json").read_text())
    assert record["configuration"]["scenes"] == ["paper"]
    assert record["earlier"][0]["configuration"]["scenes"] == ["free-boundary"]
    rates = pd.read_csv(results_copy / "rates.csv")
    assert {"paper", "free-boundary"} <= set(rates["scene"])

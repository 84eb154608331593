"""Run files (docs/command-line.md, "Run files"): a run's configuration written from a finished
run repeats it bit for bit; keys are the command line's options; flags override them; old
results folders keep working under their old sequence keys."""

import json

import pandas as pd
import pytest

from bench.cli import main
from bench.matrix import RunConfig, run
from bench.matrix.config_files import read_run_file, run_file_text, save_run_file
from bench.matrix.store import read_results

# a small run: 3 uniform levels of free-boundary, two estimators; splu, a sequential
# factorisation, so that two runs add in the same order (threaded PARDISO need not)
RUN = ["run", "--scene", "free-boundary", "--strategy", "uniform", "--estimator",
       "residual,averaging", "--max-dofs", "600", "--backend", "splu"]
VARYING = {"run_id"}  # differs between any two runs; t_* columns are wall times


def numbers(folder) -> pd.DataFrame:
    table = read_results(folder)
    kept = [c for c in table.columns if c not in VARYING and not c.startswith("t_")]
    return table[kept].sort_values(["estimator", "level"]).reset_index(drop=True)


@pytest.fixture(scope="module")
def first(tmp_path_factory):
    base = tmp_path_factory.mktemp("config")
    assert main([*RUN, "--out", str(base / "first"), "--save-config",
                 str(base / "saved.toml")]) == 0
    return base


@pytest.mark.parametrize("source", ["saved.toml", "first/run.json"])
def test_a_run_file_from_a_finished_run_repeats_it_bit_for_bit(first, source):
    again = first / f"again-{source.replace('/', '-')}"
    assert main(["run", "--config", str(first / source), "--out", str(again)]) == 0
    a, b = numbers(first / "first"), numbers(again)
    assert len(a) == 6  # 3 levels x 2 estimators
    pd.testing.assert_frame_equal(a, b, check_exact=True)  # the same bits, not a tolerance


def test_options_override_the_keys_of_a_run_file(first, capsys):
    out = first / "smaller"
    assert main(["run", "--config", str(first / "saved.toml"), "--max-dofs", "300",
                 "--estimator", "residual", "--out", str(out)]) == 0
    record = json.loads((out / "run.json").read_text())["configuration"]
    assert record["max_dofs"] == 300 and record["estimators"] == ["residual"]
    assert record["scenes"] == ["free-boundary"] and record["backend"] == "splu"  # the file's


def test_a_run_file_round_trips_every_field(tmp_path):
    config = RunConfig(scenes=("paper:poisson_ratio=0.3|0.45", "hertz"), orders=(1, 2),
                       strategies=("uniform",), max_dofs=1234, theta=0.25, nested=False,
                       marking="maximum", target_error=None, reference_dofs=5000,
                       crosscheck_dofs=7, out="somewhere", workers=3, cache="cache dir")
    path = save_run_file(config, tmp_path / "run.toml")
    assert RunConfig(**read_run_file(path)).record() == config.record()
    assert "cold-start = true" in run_file_text(config)  # the option's sense, not the field's


def test_an_unknown_key_is_refused_naming_the_valid_ones(tmp_path, capsys):
    path = tmp_path / "bad.toml"
    path.write_text('scene = ["paper"]\nmax_dof = 300\n')
    assert main(["run", "--config", str(path)]) == 2
    error = capsys.readouterr().err.strip()
    assert len(error.splitlines()) == 1
    assert "unknown key 'max_dof'" in error and "max-dofs" in error


def test_a_file_that_is_not_toml_is_refused(tmp_path, capsys):
    path = tmp_path / "bad.toml"
    path.write_text("scene = [paper\n")
    assert main(["run", "--config", str(path)]) == 2
    assert "cannot be read as a run file" in capsys.readouterr().err


def test_sequences_stored_under_the_old_keys_are_reused_once_with_a_note(tmp_path, capsys):
    config = RunConfig(scenes=("free-boundary",), strategies=("uniform",), max_dofs=300,
                       out=str(tmp_path / "old"))
    result = run(config)
    [spec] = config.specs()
    assert spec.legacy_key != spec.key
    for partition in (tmp_path / "old" / "sequences").glob("*.parquet"):  # as written before
        table = pd.read_parquet(partition)
        table["sequence_key"] = spec.legacy_key
        table.to_parquet(partition.with_name(f"{spec.legacy_key}.parquet"))
        partition.unlink()
    for name in ("results.parquet", "results.csv"):
        (tmp_path / "old" / name).unlink()  # rebuilt from the partitions
    capsys.readouterr()
    again = run(config)
    assert again.reused == (spec.legacy_key,) and not again.rows
    assert "stored under the key of an earlier version" in capsys.readouterr().err
    assert len(again.table) == len(result.table)

"""Run descriptions describe, actions act: a saved run file never deletes rows; a run file's
values are checked as the command line checks its options, and refused naming the file, the
key and the value; every other bad input here is one line naming the parameter, the value and
what is allowed (docs/command-line.md, "Run files"; docs/reliability.md)."""

import pandas as pd
import pytest

import bench.verify.expected as expected_module
from bench.cli import main
from bench.cli.commands import compare_fields
from bench.cli.parser import build_parser
from bench.perf import scaling as scaling_module

FAST = ["--scene", "free-boundary", "--solver", "active-set", "--max-dofs", "300"]


def refusal(capsys) -> str:
    err = capsys.readouterr().err
    assert "Traceback" not in err
    lines = [line for line in err.splitlines() if line.startswith(("error:", "python -m"))]
    assert len(lines) >= 1, err
    return lines[-1]


def test_a_saved_run_repeated_keeps_the_rows_other_runs_added(results_copy, tmp_path, capsys):
    saved = tmp_path / "run.toml"
    assert main(["run", *FAST, "--overwrite", "--save-config", str(saved), "--out",
                 str(results_copy)]) == 0
    assert "overwrite" not in saved.read_text().split("\n", 2)[2]  # beyond the header
    assert main(["run", "--scene", "paper", "--max-dofs", "300", "--out",
                 str(results_copy)]) == 0
    rows = len(pd.read_parquet(results_copy / "results.parquet"))
    assert main(["run", "--config", str(saved), "--out", str(results_copy)]) == 0
    assert len(pd.read_parquet(results_copy / "results.parquet")) == rows


def test_an_overwrite_key_in_an_older_run_file_is_left_out_with_a_note(results_copy, tmp_path,
                                                                       capsys):
    rows = len(pd.read_parquet(results_copy / "results.parquet"))
    old = tmp_path / "old.toml"
    old.write_text('scene = ["paper"]\nmax-dofs = 300\noverwrite = true\n')
    assert main(["run", "--config", str(old), "--out", str(results_copy)]) == 0
    assert "never deletes results" in capsys.readouterr().err
    assert len(pd.read_parquet(results_copy / "results.parquet")) > rows


def test_overwrite_and_no_overwrite_together_are_refused(results_copy, capsys):
    assert main(["run", *FAST, "--overwrite", "--no-overwrite", "--out",
                 str(results_copy)]) == 2
    assert "contradict" in refusal(capsys)


@pytest.mark.parametrize("line, message", [
    ("scene = 5", "config='FILE': scene = '5': unknown scene '5'"),
    ('max-dofs = "abc"', "config='FILE': max-dofs = 'abc': max_dofs='abc' is not a positive"),
    ("max-dofs = -3", "max-dofs = '-3': max_dofs='-3' is not a positive integer"),
    ('strategy = ["sideways"]', "unknown strategy 'sideways'"),
    ("cold-start = 3", "cold-start = 3 is not true or false"),
])
def test_a_bad_run_file_value_names_the_file_and_key(tmp_path, capsys, line, message):
    path = tmp_path / "bad.toml"
    path.write_text(line + "\n")
    assert main(["run", "--config", str(path), "--out", str(tmp_path / "r")]) == 2
    assert message.replace("FILE", str(path)) in refusal(capsys)
    assert not (tmp_path / "r" / "results.parquet").exists()


def test_an_integer_written_as_a_float_means_the_same_in_a_file(tmp_path):
    path = tmp_path / "run.toml"
    path.write_text('scene = "free-boundary"\nmax-dofs = 3e2\n')
    assert main(["run", "--config", str(path), "--out", str(tmp_path / "r")]) == 0
    assert pd.read_parquet(tmp_path / "r" / "results.parquet")["ndofs"].max() <= 300


@pytest.mark.parametrize("argv, message", [
    (["run", *FAST, "--save-config", "FOLDER"], "save_config='FOLDER' is a folder"),
    (["export", "--results", "RESULTS", "--out", "FILE"], "--out='FILE' is a file"),
    (["run", *FAST, "--target-error", "-1e-3"], "target_error='-1e-3' is not a number > 0"),
    (["run", *FAST, "--solver", "reference", "--backend", "amg"],
     "backend='amg' applies to the fast solvers"),
    (["run", "--scene", "stick-slip:friction=coulomb:mu=1e300", "--max-dofs", "300"],
     "mu in (0, 100]"),
    (["diff", "RESULTS", "OTHER"], "have no sequence in common"),
])
def test_bad_input_is_one_line(results_copy, tmp_path, capsys, argv, message):
    (tmp_path / "FILE").write_text("")
    other = tmp_path / "OTHER"
    assert main(["run", "--scene", "paper", "--max-dofs", "300", "--out", str(other)]) == 0
    capsys.readouterr()
    names = {"FOLDER": str(tmp_path), "FILE": str(tmp_path / "FILE"),
             "RESULTS": str(results_copy), "OTHER": str(other)}
    argv = [names.get(a, a) for a in argv]
    message = message.replace("FOLDER", str(tmp_path)).replace("FILE", str(tmp_path / "FILE"))
    with pytest.raises(SystemExit) if "target_error" in message else _nothing():
        assert main([*argv, "--out", str(tmp_path / "o")] if argv[0] == "run" else argv) == 2
    assert message in refusal(capsys)


class _nothing:
    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return False


def test_scaling_readme_without_markers_is_refused_before_measuring(tmp_path, monkeypatch,
                                                                    capsys):
    def measured(*args, **kwargs):
        raise AssertionError("measured before the README was checked")

    monkeypatch.setattr(scaling_module, "run_scaling", measured)
    readme = tmp_path / "README.md"
    readme.write_text("no markers here\n")
    assert main(["scaling", "--readme", str(readme), "--out", str(tmp_path / "s")]) == 2
    assert "has no <!-- scaling:start -->" in refusal(capsys)


def test_a_damaged_expected_file_is_named_in_one_line(tmp_path, monkeypatch, capsys):
    damaged = tmp_path / "expected.toml"
    damaged.write_text("[[hard]\nthis is not toml")
    monkeypatch.setattr(expected_module.load_expected, "__defaults__", (damaged,))
    assert main(["hard", "--out", str(tmp_path / "h")]) == 2
    line = refusal(capsys)
    assert str(damaged) in line and "cannot be read" in line and "reinstall" in line


@pytest.mark.parametrize("flags, overwrite", [([], True), (["--no-overwrite"], False)])
def test_compare_replaces_its_own_folder_unless_told_to_keep_it(flags, overwrite):
    args = build_parser({}).parse_args(["compare", *flags])
    args.file_fields = {}
    assert compare_fields(args)["overwrite"] is overwrite

"""Inputs that once ended in a traceback, a long wait or a silent surprise: each is refused
with one line naming the option, the value and what is allowed (exit status 2), or explained."""

import socket
import time

import pytest

from bench.cli import main
from bench.matrix import RunConfig
from bench.matrix.distributed import SCHEDULER_TIMEOUT


def one_line_error(capsys) -> str:
    err = capsys.readouterr().err
    lines = [line for line in err.splitlines() if line.startswith(("error:", "python -m"))]
    assert "Traceback" not in err and len(lines) >= 1, err
    return lines[-1]


@pytest.mark.parametrize("address", ["garbage", "tcp://", "tcp://host", "tcp://host:port",
                                     "http://127.0.0.1:8786", "tcp://127.0.0.1:70000"])
def test_a_malformed_scheduler_address_is_refused(tmp_path, capsys, address):
    with pytest.raises(SystemExit) as stop:
        main(["run", "--scheduler", address, "--out", str(tmp_path)])
    assert stop.value.code == 2
    line = one_line_error(capsys)
    assert f"scheduler={address!r}" in line and "tcp://10.0.0.5:8786" in line
    with pytest.raises(ValueError, match="is not a Dask scheduler address"):
        RunConfig(scheduler=address)


def test_a_scheduler_that_does_not_answer_is_refused_before_any_work(tmp_path, capsys):
    with socket.socket() as probe:  # a port that was free a moment ago: nothing listens
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    start = time.perf_counter()
    assert main(["run", "--scheduler", f"tcp://127.0.0.1:{port}", "--max-dofs", "200",
                 "--out", str(tmp_path / "r")]) == 2
    elapsed = time.perf_counter() - start
    line = one_line_error(capsys)
    assert f"tcp://127.0.0.1:{port}" in line and "no Dask scheduler answered" in line
    assert f"{SCHEDULER_TIMEOUT:g} s" in line
    # refused, not waited out: connection refused returns at once; the bound is the timeout
    # (2x leaves room for the interpreter's imports on a loaded machine)
    assert elapsed < 2 * SCHEDULER_TIMEOUT
    assert not (tmp_path / "r" / "sequences").exists() or \
        not any((tmp_path / "r" / "sequences").iterdir())


@pytest.mark.parametrize("item, expected", [
    ("mixed:h_over_H=2", "h_over_H=2 is not in (0, 1]"),
    ("mixed:h_over_H=../../x", "h_over_H='../../x' is not in (0, 1]"),
    ("mixed:multiplier_degree=7", "multiplier_degree=7"),
    ("penalty:epsilon_0=-1", "epsilon_0=-1"),
    ("mixed:nonsense=1", "has no parameter 'nonsense'"),
])
def test_formulation_options_are_checked_by_value_before_any_run(tmp_path, capsys, item,
                                                                 expected):
    out = tmp_path / "r"
    assert main(["run", "--formulation", item, "--solver", "active-set", "--max-dofs", "200",
                 "--out", str(out)]) == 2
    line = one_line_error(capsys)
    assert expected in line and line.count("\n") == 0
    assert not (out / "results.parquet").exists()  # no row, failed or otherwise


@pytest.mark.parametrize("command", [["run"], ["report"], ["hard", "--case", "invalid"],
                                     ["compare"]])
def test_an_empty_output_folder_is_refused(tmp_path, monkeypatch, capsys, command):
    monkeypatch.chdir(tmp_path)
    assert main([*command, "--out="]) == 2
    assert "--out='' is empty" in one_line_error(capsys)
    assert list(tmp_path.iterdir()) == []  # nothing written into the current folder
    with pytest.raises(ValueError, match="out='' is empty"):
        RunConfig(out="")


def test_a_run_without_truth_says_why_errors_are_not_measured(tmp_path, capsys, monkeypatch):
    # an empty cache: one that holds compare's references would be taken (and say so)
    monkeypatch.setenv("SIGNORINI_BENCH_CACHE", str(tmp_path / "cache"))
    assert main(["run", "--solver", "active-set", "--max-dofs", "200",
                 "--out", str(tmp_path)]) == 0
    err = capsys.readouterr().err
    assert err.count("has no exact solution") == 1 and "--reference-dofs" in err
    # a scene with an exact solution needs no reference: no note
    assert main(["run", "--scene", "free-boundary", "--solver", "active-set", "--max-dofs",
                 "200", "--out", str(tmp_path / "exact")]) == 0
    assert "has no exact solution" not in capsys.readouterr().err


def test_building_a_reference_says_so_in_two_lines_off_a_terminal(tmp_path, monkeypatch,
                                                                   capsys):
    monkeypatch.setenv("SIGNORINI_BENCH_CACHE", str(tmp_path / "cache"))
    assert main(["run", "--solver", "active-set", "--max-dofs", "200", "--reference-dofs",
                 "3000", "--out", str(tmp_path / "r")]) == 0
    err = capsys.readouterr().err
    assert "building the mixed-p3 reference of scene 'paper'" in err
    assert "built the 'paper' reference:" in err and "[reference" not in err  # no level lines
    # cached now: loaded, not rebuilt
    assert main(["run", "--solver", "active-set", "--max-dofs", "200", "--reference-dofs",
                 "3000", "--out", str(tmp_path / "r")]) == 0
    assert "building" not in capsys.readouterr().err

"""The documented baseline workflow of pytest-benchmark (docs/solvers.md, "Benchmarks"): save a
baseline JSON, then compare a second run against it with a regression threshold."""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.slow

BENCHMARKS = str(Path(__file__).with_name("test_benchmarks.py"))
ROOT = Path(__file__).parents[2]  # the project's pytest configuration and imports


def _pytest(tmp_path, *options):
    command = [sys.executable, "-m", "pytest", BENCHMARKS, "-q", "-p", "no:cacheprovider",
               "--benchmark-enable", "--benchmark-only", "-n", "0", "--dist", "no",
               "-k", "1e4 and (linear or fast)",
               f"--benchmark-storage={tmp_path / 'store'}", *options]
    # a pytest-xdist worker's variables would make pytest-benchmark in the child think it runs
    # under xdist too (PYTEST_XDIST_WORKER), and turn itself off
    env = {k: v for k, v in os.environ.items() if not k.startswith("PYTEST_XDIST")}
    return subprocess.run(command, capture_output=True, text=True, cwd=ROOT, env=env)


def test_a_saved_baseline_is_compared_and_gates_regressions(tmp_path):
    saved = _pytest(tmp_path, "--benchmark-save=baseline")
    assert saved.returncode == 0, saved.stdout + saved.stderr
    [baseline] = (tmp_path / "store").rglob("0001_baseline.json")
    names = {b["name"] for b in json.loads(baseline.read_text())["benchmarks"]}
    assert {"test_linear_solve[1e4]", "test_fast_contact_solve[1e4]"} <= names
    # the same code again must pass the gate. Four runs of these 10^4 workloads (5 rounds each)
    # on the 2-core machine put the fast contact solve's median between 60 and 128 ms, a factor
    # 2.1; +300 % leaves room for a loaded CI machine while still catching a 4x regression
    same = _pytest(tmp_path, "--benchmark-compare=0001", "--benchmark-compare-fail=median:300%")
    assert same.returncode == 0, same.stdout + same.stderr
    assert "0001_baseli" in same.stdout and "(NOW)" in same.stdout  # both rows in the table

"""``run`` without --reference-dofs measures errors against the reference ``compare`` cached
(bench.matrix.run.cached_reference_dofs), and only against one that can judge the run."""

import importlib
import math

import pandas as pd

from bench.cli import main

matrix_run = importlib.import_module("bench.matrix.run")  # the package exports run() by name

BUDGET = 3000  # stands for compare's budget: a reference that builds in about a second


def test_run_reuses_the_reference_compare_cached(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("SIGNORINI_BENCH_CACHE", str(tmp_path / "cache"))
    monkeypatch.setattr(matrix_run, "COMPARE_REFERENCE_DOFS", BUDGET)
    args = ["run", "--scene", "paper", "--max-dofs", "200", "--solver", "active-set"]
    assert main([*args, "--out", str(tmp_path / "none")]) == 0  # nothing cached: no errors
    assert "errors measured against the references compare cached" not in \
        capsys.readouterr().err
    assert pd.read_parquet(tmp_path / "none" / "results.parquet")["energy_error"].isna().all()
    # compare's reference, as compare caches it
    assert main([*args, "--reference-dofs", str(BUDGET), "--out", str(tmp_path / "c")]) == 0
    capsys.readouterr()
    assert main([*args, "--out", str(tmp_path / "r")]) == 0
    assert f"as with --reference-dofs {BUDGET}" in capsys.readouterr().err
    errors = pd.read_parquet(tmp_path / "r" / "results.parquet")["energy_error"]
    assert errors.notna().all() and all(math.isfinite(e) and e > 0 for e in errors)


def test_a_cached_reference_too_coarse_for_the_run_is_not_taken(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("SIGNORINI_BENCH_CACHE", str(tmp_path / "cache"))
    monkeypatch.setattr(matrix_run, "COMPARE_REFERENCE_DOFS", BUDGET)
    args = ["run", "--scene", "paper", "--solver", "active-set"]
    assert main([*args, "--max-dofs", "200", "--reference-dofs", str(BUDGET),
                 "--out", str(tmp_path / "c")]) == 0
    capsys.readouterr()
    # a P3 run to 2000 DOFs needs a P3 reference of 20 000: more than the cached one has, so
    # the run measures no errors
    assert main([*args, "--order", "3", "--max-dofs", "2000", "--out", str(tmp_path / "r")]) == 0
    assert "compare cached" not in capsys.readouterr().err

"""Plugins: the example plugin package (a scene, a formulation, an estimator), installed with
pip, and a plugin of every other kind (a solver, a sparse back-end, a hard case) reach
``list``, the matrix, the report and ``export`` with no edit inside the package; a plugin that
fails to import is named and skipped."""

import os
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest

from bench.measure.contact import SOLVED_STATUSES as SOLVED

ROOT = Path(__file__).parents[2]
EXAMPLE = "signorini-bench-example-plugin"

KINDS_MODULE = '''
import numpy as np
from scipy import linalg
from bench.hard import hard_case
from formulations.solvers import get_solver, register_solver
from formulations.solvers.backends import Backend, CondensedFactor, register_backend

register_solver("active-set-again", "test plugin: the active-set solver again")(
    get_solver("active-set"))


def factorise(K):
    factor = linalg.cho_factor(K.toarray(), lower=True)
    return lambda b: linalg.cho_solve(factor, b)


def condense(K, interior, contact):
    dense = K.toarray()
    schur = dense[np.ix_(contact, contact)] - dense[np.ix_(contact, interior)] @ \\
        np.linalg.solve(dense[np.ix_(interior, interior)], dense[np.ix_(interior, contact)])
    return CondensedFactor("dense", contact, factorise(K), linalg.cholesky(schur, lower=True))


register_backend(Backend("dense", rank=9, factorise=factorise, condense=condense,
                         description="test plugin: dense Cholesky"))
hard_case("plugin-case", "test plugin: one accurate record")(lambda: [dict(
    case="plugin-case", scene="-", formulation="-", solver="-", variant="",
    verdict="accurate")])
'''
BROKEN_MODULE = '''
from formulations import register_formulation
from formulations.methods.mixed import discretise
register_formulation("half-registered", "registered before the import fails")(discretise)
raise RuntimeError("this plugin is broken on purpose")
'''


def fake_distribution(site: Path, name: str, module: str, text: str, groups: dict) -> None:
    """A distribution as pip leaves it: the module and a dist-info with its entry points."""
    (site / f"{module}.py").write_text(text)
    info = site / f"{name.replace('-', '_')}-0.1.dist-info"
    info.mkdir()
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {name}\nVersion: 0.1\n")
    (info / "entry_points.txt").write_text("".join(
        f"[{group}]\n{point} = {module}\n" for group, point in groups.items()))


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    site = tmp_path_factory.mktemp("site")
    subprocess.run([sys.executable, "-m", "pip", "install", "--quiet", "--no-deps",
                    "--target", str(site), str(ROOT / "examples" / "plugin")], check=True)
    fake_distribution(site, "kinds-plugin", "kinds_plugin", KINDS_MODULE, {
        "signorini_bench.solvers": "active-set-again",
        "signorini_bench.backends": "dense", "signorini_bench.hard_cases": "plugin-case"})
    fake_distribution(site, "broken-plugin", "broken_plugin", BROKEN_MODULE,
                      {"signorini_bench.formulations": "broken"})
    return site


def bench(site: Path, *args: str, cwd: Path) -> subprocess.CompletedProcess:
    paths = os.pathsep.join([str(site), str(ROOT), os.environ.get("PYTHONPATH", "")])
    return subprocess.run([sys.executable, "-m", "bench", *args], cwd=cwd, text=True,
                          capture_output=True, env={**os.environ, "PYTHONPATH": paths})


def test_list_names_each_plugin_unit_and_the_broken_plugin(site, tmp_path):
    done = bench(site, "list", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    for name in ("punch", "penalty-soft", "residual-volume"):
        assert f"[plugin {EXAMPLE}]" in next(line for line in done.stdout.splitlines()
                                             if line.startswith(f"  {name} "))
    for name in ("active-set-again", "dense", "plugin-case"):
        assert any(line.startswith(f"  {name} ") and "[plugin kinds-plugin]" in line
                   for line in done.stdout.splitlines())
    assert "half-registered" not in done.stdout  # undone with the failed import
    assert ("plugin 'broken-plugin' (entry point 'broken' in signorini_bench.formulations) "
            "failed to import and is skipped: RuntimeError: this plugin is broken on purpose"
            in done.stderr) and "Traceback" not in done.stderr


@pytest.mark.slow  # run, report and export end to end: ~27 s
def test_plugin_units_run_in_the_matrix_the_report_and_export(site, tmp_path):
    done = bench(site, "run", "--scene", "paper,punch", "--formulation", "mixed,penalty-soft",
                 "--solver", "active-set,active-set-again", "--estimator",
                 "residual,residual-volume", "--strategy", "uniform", "--max-dofs", "600",
                 "--backend", "dense", "--out", "r", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    table = pd.read_parquet(tmp_path / "r" / "results.parquet")
    assert set(table["scene"]) == {"paper", "punch"}
    assert set(table["formulation"]) == {"mixed", "penalty-soft"}
    assert set(table["solver"]) == {"active-set", "active-set-again"}
    assert table["status"].isin(SOLVED).all() and (table["backend"] == "dense").all()
    volume = table[table["estimator"] == "residual-volume"].set_index(
        ["scene", "formulation", "solver", "level"])
    full = table[table["estimator"] == "residual"].set_index(volume.index.names)
    # eta_0 alone: the residual estimator's own eta_0 (same solution, same formula; round-off)
    assert (volume["eta"] - full.loc[volume.index, "eta_0"]).abs().max() < 1e-12 * full[
        "eta_0"].max()
    assert bench(site, "report", "--results", "r", "--out", "rep", cwd=tmp_path).returncode == 0
    readme = (tmp_path / "rep" / "README.md").read_text()
    assert all(name in readme for name in ("punch", "penalty-soft", "residual-volume",
                                           "active-set-again"))
    assert bench(site, "export", "--results", "r", "--out", "ex", cwd=tmp_path).returncode == 0
    exported = {path.name for path in (tmp_path / "ex").glob("*.vtu")}
    assert "punch-penalty-soft-active-set-again-residual-volume-uniform-1.vtu" in exported
    hard = bench(site, "hard", "--case", "plugin-case", "--out", "h", cwd=tmp_path)
    assert hard.returncode == 0, hard.stderr
    assert "plugin-case" in (tmp_path / "h" / "hard.md").read_text()

"""One test per guard: a bad input or a fault ends in a clear one-line refusal or a correct
recovery, never in a traceback or a machine out of memory."""

import os
import shutil
import signal
import time
from dataclasses import replace

import numpy as np
import pandas as pd
import pytest

import bench.sequence.loop as loop_module
import bench.sequence.memory as memory_module
from bench.cli import main
from bench.matrix.artifacts import file_stem
from bench.matrix.folder_state import FolderState
from bench.matrix.store import ResultStore
from bench.measure.contact import SOLVED_STATUSES as SOLVED
from bench.report import write_report
from bench.sequence.loop import LoopConfig, run_sequence
from bench.sequence.memory import available_gib, memory_line, predict_peak_gib
from bench.truth import cache
from conftest import folder_bytes, interruptible_bench, square_scene
from formulations.solvers import backends
from scenes import SceneError, get_scene

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def assembled_sizes(monkeypatch) -> list[int]:
    """Record the DOFs of every discretisation the loop builds."""
    sizes, real = [], loop_module.get_formulation

    def recording(name):
        discretise = real(name)

        def wrapped(scene, mesh, **options):
            disc = discretise(scene, mesh, **options)
            sizes.append(disc.ndofs)
            return disc
        return wrapped
    monkeypatch.setattr(loop_module, "get_formulation", recording)
    return sizes


@pytest.mark.parametrize("strategy", ["uniform", "adaptive"])
def test_no_level_over_the_dof_budget_is_assembled(monkeypatch, strategy):
    sizes = assembled_sizes(monkeypatch)
    rows = [r.row for r in run_sequence(get_scene("paper"), "mixed", "active-set", "residual",
                                        LoopConfig(strategy=strategy, max_dofs=2500))]
    assert max(sizes) <= 2500 and sizes == [r.ndofs for r in rows]
    assert rows[-1].status == "ok"


def test_a_level_that_would_not_fit_in_memory_is_refused_before_it_is_built(monkeypatch):
    sizes = assembled_sizes(monkeypatch)
    monkeypatch.setattr(memory_module, "iterative_route", lambda *args: None)  # none fits
    limit = predict_peak_gib(2112, "active-set", backends.check_backend(None)) * 1.01
    rows = [r.row for r in run_sequence(
        get_scene("paper"), "mixed", "active-set", "residual",
        LoopConfig(strategy="uniform", max_dofs=10**8, max_memory_gib=limit))]
    last = rows[-1]
    # paper's 40 and 144 DOFs miss part of the contact (bench.measure.contact)
    assert all(r.status in SOLVED for r in rows[:-1]) and len(rows) == 5
    assert rows[-2].status == "ok" and rows[-2].ndofs == 2112
    assert last.status == "failed" and last.ndofs == 8320 and 8320 not in sizes
    assert last.reason.startswith("memory: level 4 needs ~") and "available" in last.reason


@pytest.mark.slow  # ~10 s: a level large enough for the route to matter
@pytest.mark.skipif("amg" not in backends.available_backends(), reason="pyamg missing")
def test_a_level_too_large_for_a_factorisation_is_solved_by_the_iterative_back_end(
        monkeypatch):
    direct = backends.check_backend(None)

    def predicted(ndofs, solver, backend, order=1, dim=2):  # only level 4 is too large
        return 100.0 if ndofs > 2112 and not backends.iterative(backend) else 0.1
    monkeypatch.setattr(memory_module, "predict_peak_gib", predicted)
    rows = [r.row for r in run_sequence(
        get_scene("paper"), "mixed", "active-set", "residual",
        LoopConfig(strategy="uniform", max_dofs=8400, max_memory_gib=1.0))]
    assert all(r.status in SOLVED for r in rows) and len(rows) == 5
    assert rows[-1].status == "ok" and rows[-1].ndofs == 8320
    assert [r.backend for r in rows] == [direct] * 4 + ["amg"]
    assert rows[-1].reason == (f"memory: level 4 needs ~100.00 GiB (8320 DOFs, {direct}), "
                               "1.00 available; solved by amg instead")
    # the reference uses no back-end: it is refused, not rerouted
    assert memory_module.memory_route(4, 8320, "reference", direct, 1.0).refusal


@pytest.mark.slow  # ~10 s, as above
@pytest.mark.skipif("amg" not in backends.available_backends(), reason="pyamg missing")
def test_the_route_is_chosen_before_the_assembly_takes_its_memory(monkeypatch):
    """A level admitted on the iterative back-end stays there when its own assembly leaves
    less memory free: asked again after it, the route was a refusal, and the level fell back
    to the configured direct back-end (a paper-3d P2 reference past 1.4e6 DOFs then failed on
    a dense Schur block of 16.6 GiB)."""
    built = assembled_sizes(monkeypatch)

    def predicted(ndofs, solver, backend, order=1, dim=2):  # only level 4 is too large
        return 100.0 if ndofs > 2112 and not backends.iterative(backend) else 0.1

    def free_memory():  # the assembly of level 4 takes what amg would need
        return 0.05 if 8320 in built else 1.0
    monkeypatch.setattr(memory_module, "predict_peak_gib", predicted)
    monkeypatch.setattr(memory_module, "available_gib", free_memory)
    rows = [r.row for r in run_sequence(get_scene("paper"), "mixed", "active-set", "residual",
                                        LoopConfig(strategy="uniform", max_dofs=8400))]
    assert rows[-1].ndofs == 8320 and rows[-1].status == "ok"
    assert rows[-1].backend == "amg" and "solved by amg instead" in rows[-1].reason


def test_memory_model_matches_the_scaling_table_within_1_5():
    table = pd.read_csv(os.path.join(ROOT, "reports", "scaling.csv"))
    for _, row in table.iterrows():
        predicted = memory_line(row["backend"]).peak_gib(row["ndofs"])
        assert 1 / 1.5 <= predicted / row["peak_gib_without_reference"] <= 1.5, row["ndofs"]
    assert 0 < available_gib() < float("inf")


def test_reference_budget_too_small_for_two_levels_is_refused(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("SIGNORINI_BENCH_CACHE", str(tmp_path / "cache"))
    assert main(["run", "--reference-dofs", "53", "--out", str(tmp_path / "r")]) == 2
    err = capsys.readouterr().err
    assert "reference_dofs=53" in err and "one level" in err and "Traceback" not in err


def test_a_degenerate_reference_is_refused_before_any_run(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("SIGNORINI_BENCH_CACHE", str(tmp_path / "cache"))
    out = tmp_path / "r"
    assert main(["run", "--reference-dofs", "60", "--max-dofs", "300", "--out", str(out)]) == 2
    assert "312 DOFs" in capsys.readouterr().err  # the P3 reference's first level
    assert not (out / "results.parquet").exists()  # refused before the runs start


def test_a_reference_coarser_than_ten_times_the_runs_is_refused(tmp_path, monkeypatch, capsys):
    # only for runs of the reference's own order (P3): P1 runs are judged row by row
    monkeypatch.setenv("SIGNORINI_BENCH_CACHE", str(tmp_path / "cache"))
    assert main(["run", "--reference-dofs", "3000", "--max-dofs", "2000", "--order", "3",
                 "--out", str(tmp_path / "r")]) == 2
    assert "is not 10x finer than the runs it would judge" in capsys.readouterr().err


@pytest.mark.parametrize("damage", ["truncate", "garble", "checksum"])
def test_a_corrupt_cached_reference_is_named_deleted_and_rebuilt(tmp_path, monkeypatch, capsys,
                                                               damage):
    monkeypatch.setenv("SIGNORINI_BENCH_CACHE", str(tmp_path))
    scene = get_scene("paper")
    first = cache.load_or_build(scene, 3000)
    path = next(tmp_path.glob("*.npz"))
    data = path.read_bytes()
    if damage == "truncate":
        path.write_bytes(data[: len(data) // 2])
    elif damage == "garble":
        path.write_bytes(data[:100] + bytes(200) + data[300:])
    else:
        path.with_suffix(".sha256").unlink()
    again = cache.load_or_build(scene, 3000)
    assert f"cached reference {path} is corrupt" in capsys.readouterr().err
    assert np.array_equal(again.u, first.u)
    assert cache.load_reference(path, again.key).ndofs == first.ndofs  # sound again


@pytest.mark.parametrize("command", [["run"], ["hard", "--case", "invalid"], ["verify"],
                                     ["compare"]])
def test_an_output_folder_that_is_a_file_is_refused_first(tmp_path, capsys, command):
    target = tmp_path / "taken"
    target.write_text("a file")
    assert main([*command, "--out", str(target)]) == 2
    assert "is a file, not a folder" in capsys.readouterr().err


@pytest.mark.parametrize("folder", ["/proc/signorini-bench", "/proc/1/nonexistent/mount"])
def test_an_output_folder_that_cannot_be_written_is_refused_first(capsys, folder):
    assert main(["hard", "--out", folder]) == 2  # before any case runs
    err = capsys.readouterr().err
    assert "cannot be written" in err and "Traceback" not in err


@pytest.fixture(scope="module")
def small_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("small") / "res"
    assert main(["run", "--max-dofs", "300", "--out", str(out)]) == 0
    return out


@pytest.fixture
def small_results(small_run, tmp_path):
    """A copy of one small run, for a test to damage."""
    return shutil.copytree(small_run, tmp_path / "res")


def test_a_truncated_parquet_without_partitions_falls_back_to_its_csv_mirror(small_results,
                                                                             tmp_path, capsys):
    parquet = small_results / "results.parquet"
    rows = len(pd.read_csv(small_results / "results.csv"))
    shutil.rmtree(small_results / "sequences")  # a folder of an older version: tables only
    parquet.write_bytes(parquet.read_bytes()[:200])
    assert main(["report", "--results", str(small_results), "--out", str(tmp_path / "rep")]) == 0
    assert "using its CSV mirror" in capsys.readouterr().err
    # a run into the folder takes the CSV rows over as a partition and rebuilds the tables
    assert main(["run", "--max-dofs", "300", "--out", str(small_results)]) == 0
    assert len(pd.read_parquet(parquet)) == rows


def test_both_tables_broken_without_partitions_are_named(small_results, tmp_path, capsys):
    shutil.rmtree(small_results / "sequences")
    (small_results / "results.parquet").write_bytes(b"PAR1 garbage")
    (small_results / "results.csv").write_bytes(b"\x00\x01 not a table")
    assert main(["report", "--results", str(small_results), "--out", str(tmp_path / "x")]) == 2
    err = capsys.readouterr().err
    assert "results.parquet is unreadable" in err and "--overwrite" in err


@pytest.mark.parametrize("damage", ["both-garbled", "header-only-csv", "missing", "stale"])
def test_damaged_tables_are_rebuilt_from_the_partitions(small_results, tmp_path, capsys,
                                                        damage):
    parquet, csv = small_results / "results.parquet", small_results / "results.csv"
    rows = len(pd.read_parquet(parquet))
    if damage == "both-garbled":
        parquet.write_bytes(b"PAR1 garbage")
        csv.write_bytes(b"\x00\x01 not a table")
    elif damage == "header-only-csv":  # the case that once gave "0 result rows"
        parquet.write_bytes(parquet.read_bytes()[:4])
        csv.write_text("scene,level\n")
    elif damage == "missing":
        parquet.unlink()
        csv.unlink()
    else:  # readable, but a row short of the partitions
        pd.read_parquet(parquet).iloc[:-1].to_parquet(parquet)
    before = folder_bytes(small_results)
    assert main(["report", "--results", str(small_results), "--out", str(tmp_path / "r")]) == 0
    assert "read from the partitions" in capsys.readouterr().err
    assert f"{rows} result rows" in (tmp_path / "r" / "README.md").read_text()
    assert folder_bytes(small_results) == before  # a reader writes nothing into the folder
    ResultStore(small_results).consolidate()  # what the next run into it does
    assert len(pd.read_parquet(parquet)) == len(pd.read_csv(csv)) == rows
    main(["report", "--results", str(small_results), "--out", str(tmp_path / "r")])
    assert "note" not in capsys.readouterr().err  # sound again: read as it is


def test_names_from_a_results_table_cannot_escape_the_report_folder(small_results, tmp_path):
    table = pd.read_parquet(small_results / "results.parquet")
    table["scene"] = "../../escaped"
    out = tmp_path / "deep" / "report"
    write_report(table, out, small_results)
    written = list(tmp_path.rglob("*escaped*"))
    assert written and all(out in p.parents for p in written)
    assert file_stem("../../X", "pressure") == "______X-pressure"


def test_a_clamp_that_meets_gamma_c_after_refinement_fails_with_the_cause():
    base = square_scene(lambda x: np.full(x.shape[1:], -0.01))  # clamped on top
    scene = replace(base, is_dirichlet=lambda x: (np.abs(x[1] - 1) < 1e-10)
                    | ((np.abs(x[1] + 1) < 1e-10) & (np.abs(x[0] - 0.3125) < 1e-3)))
    for formulation in ("mixed", "vi"):
        with pytest.raises(SceneError, match="overlapping the contact boundary on the mesh "
                                             "of level 2"):
            list(run_sequence(scene, formulation, "reference", "residual",
                              LoopConfig(strategy="uniform")))


def test_a_gap_that_is_not_finite_after_refinement_is_named():
    scene = square_scene(lambda x: np.where(np.abs(x[0] - 0.3125) < 1e-3, np.nan, -0.01))
    with pytest.raises(SceneError, match=r"gap='nan at x=\[0.3125, -1.0\] on the mesh of "
                                         r"level 2' is not finite"):
        list(run_sequence(scene, "mixed", "active-set", "residual",
                          LoopConfig(strategy="uniform")))


def test_numbers_as_users_write_them():
    scene = get_scene("paper", young_modulus=np.float32(7e4), initial_divisions=np.int64(4))
    assert scene.parameters["initial_divisions"] == 4 and scene.material.lame[1] > 0
    with pytest.raises(SceneError, match="young_modulus=True is not a finite number"):
        get_scene("paper", young_modulus=True)
    with pytest.raises(SceneError, match="initial_divisions=True is not an integer"):
        get_scene("paper", initial_divisions=True)


def test_duplicate_names_run_once_and_integers_may_be_written_as_floats(tmp_path, capsys):
    out = tmp_path / "r"
    assert main(["run", "--formulation", "mixed,mixed", "--max-dofs", "1e3",
                 "--out", str(out)]) == 0
    assert "formulation 'mixed' given 2 times; running it once" in capsys.readouterr().err
    table = pd.read_parquet(out / "results.parquet")
    assert table.groupby("level").size().max() == 1 and table["ndofs"].max() <= 1000
    with pytest.raises(SystemExit):
        main(["run", "--max-dofs", "1.5"])
    assert "max_dofs='1.5' is not a positive integer" in capsys.readouterr().err


def test_scaling_with_a_missing_backend_is_refused(monkeypatch, tmp_path, capsys):
    monkeypatch.setattr(backends, "available_backends", lambda: ("splu",))
    assert main(["scaling", "--backend", "cholmod", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert "backend='cholmod' is not available" in err and "Traceback" not in err


def test_sigint_ends_with_one_line_and_keeps_every_finished_row(tmp_path):
    out = tmp_path / "r"
    process = interruptible_bench("run", "--strategy", "uniform", "--max-dofs", "2000000",
                                  "--solver", "reference", "--out", str(out), cwd=tmp_path)
    deadline = time.time() + 120
    while time.time() < deadline:  # wait for three finished rows, in the sequence's partition
        if (out / "sequences").exists() and len(FolderState.read(out).record()) >= 3:
            break
        time.sleep(0.2)
    process.send_signal(signal.SIGINT)
    _, err = process.communicate(timeout=120)
    assert process.returncode == 130, err
    assert "Traceback" not in err and "interrupted: every finished row is kept" in err
    table = pd.read_parquet(out / "results.parquet")
    assert len(table) >= 3 and table["status"].isin(SOLVED).all()


@pytest.mark.long
def test_a_uniform_run_to_twice_the_machine_stops_at_the_last_level_that_fits(tmp_path):
    # measured on a 24 GiB machine: levels to 2 099 200 DOFs (peak 11.2 GiB), then level 9
    # (8 392 704 DOFs, ~40 GiB predicted) refused; takes about 3 minutes
    backend = backends.check_backend(None)
    line = memory_line(backend)
    capacity = int((available_gib() - line.base_gib) / line.per_dof_gib)
    out = tmp_path / "r"
    assert main(["run", "--strategy", "uniform", "--solver", "active-set", "--max-dofs",
                 str(2 * capacity), "--out", str(out)]) == 1
    table = pd.read_parquet(out / "results.parquet")
    last, fitted = table.iloc[-1], table.iloc[:-1]
    assert (fitted["status"] == "ok").all() and last["status"] == "failed"
    assert last["reason"].startswith("memory: ") and last["ndofs"] > capacity
    assert fitted["ndofs"].max() <= capacity

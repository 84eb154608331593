"""``python -m bench diff OLD NEW``: the same run twice agrees exactly; a moved number is found,
named and judged against --rtol; a mesh that parts is reported from its level on."""

import shutil

import pandas as pd
import pytest

from bench.cli import main
from bench.matrix.diff import diff_results
from bench.matrix.store import read_results


@pytest.fixture(scope="module")
def folders(tmp_path_factory):
    base = tmp_path_factory.mktemp("diff")
    for name in ("old", "new"):
        assert main(["run", "--scene", "free-boundary", "--formulation", "mixed", "--solver",
                     "active-set", "--strategy", "uniform,adaptive", "--max-dofs", "600",
                     "--out", str(base / name)]) == 0
    return base


def perturbed(folders, tmp_path, column, level, factor):
    """A copy of the new folder with one number of the adaptive sequence changed."""
    copy = tmp_path / "changed"
    shutil.copytree(folders / "new", copy)
    partition = next(p for p in (copy / "sequences").glob("*.parquet")
                     if (pd.read_parquet(p)["strategy"] == "adaptive").all())
    table = pd.read_parquet(partition)
    table.loc[table["level"] == level, column] *= factor
    table.to_parquet(partition)
    (copy / "results.parquet").unlink()  # rebuilt from the partitions
    return copy


def test_the_same_run_twice_agrees_exactly(folders, capsys):
    table = diff_results(folders / "old", folders / "new")
    assert len(table) == 2 and (table["levels"] > 1).all()
    # the same code twice: equal to round-off (a threaded factorisation need not add in the
    # same order twice; measured 0.0)
    assert (table["max_relative_difference"] <= 1e-12).all()
    assert (table["mesh_differs_from_level"] == -1).all()
    assert main(["diff", str(folders / "old"), str(folders / "new")]) == 0
    assert "2 sequences compared" in capsys.readouterr().out


def test_a_moved_number_is_found_and_judged_by_rtol(folders, tmp_path, capsys):
    changed = perturbed(folders, tmp_path, "eta", 1, 1.0 + 1e-6)
    table = diff_results(folders / "old", changed).set_index("strategy")
    assert table.loc["adaptive", "worst_column"] == "eta"
    # |a - a (1 + 1e-6)| / (a (1 + 1e-6)) = 1e-6 / (1 + 1e-6), to round-off
    assert table.loc["adaptive", "max_relative_difference"] == pytest.approx(1e-6, rel=1e-5)
    assert table.loc["uniform", "max_relative_difference"] <= 1e-12  # untouched: round-off
    assert main(["diff", str(folders / "old"), str(changed)]) == 1
    assert main(["diff", str(folders / "old"), str(changed), "--rtol", "1e-5"]) == 0
    capsys.readouterr()


def test_a_mesh_that_parts_is_compared_only_before_it(folders, tmp_path):
    last = int(read_results(folders / "new").query("strategy == 'adaptive'")["level"].max())
    changed = perturbed(folders, tmp_path, "ndofs", last, 2)
    row = diff_results(folders / "old", changed).set_index("strategy").loc["adaptive"]
    assert row["mesh_differs_from_level"] == last
    assert row["same_mesh_levels"] == last  # levels 0 .. last - 1
    assert row["max_relative_difference"] <= 1e-12  # untouched before it: round-off

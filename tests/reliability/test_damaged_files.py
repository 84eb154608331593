"""Every file the suite reads can be damaged: sequence files, level artifacts, tables, TOML
expressions and mesh files are each named in one line with what to do, never a traceback and
never trusted when stale (README, "Reliability")."""

import socket
import threading

import meshio
import numpy as np
import pandas as pd
import pytest

from bench.cli import main
from bench.matrix.distributed import SchedulerError, check_scheduler
from bench.matrix.store import read_results
from conftest import folder_bytes
from scenes import SceneError
from scenes.expressions import Expression, ExpressionError
from scenes.mesh_file import read_mesh_file


def damage(path) -> None:
    path.write_bytes(path.read_bytes()[:100])


def test_a_damaged_sequence_file_is_read_from_intact_tables_and_restored_by_a_run(
        results_copy, tmp_path, capsys):
    partition = sorted((results_copy / "sequences").glob("*.parquet"))[0]
    rows = len(pd.read_parquet(partition))
    total = len(pd.read_parquet(results_copy / "results.parquet"))
    damage(partition)
    before = folder_bytes(results_copy)
    assert main(["report", "--results", str(results_copy), "--out", str(tmp_path / "rep")]) == 0
    err = capsys.readouterr().err
    assert f"its {rows} rows are in the folder's results table" in err and "Traceback" not in err
    assert f"{total} result rows" in (tmp_path / "rep" / "README.md").read_text()
    assert folder_bytes(results_copy) == before  # the reader wrote nothing
    assert main(["run", "--scene", "free-boundary", "--formulation", "vi,mixed", "--solver",
                 "active-set", "--max-dofs", "300", "--out", str(results_copy)]) == 0
    assert "written back" in capsys.readouterr().err
    assert len(pd.read_parquet(partition)) == rows  # the writer restored it, nothing rerun


def test_a_damaged_sequence_file_without_a_copy_is_set_aside_and_rerun(results_copy, capsys):
    partition = sorted((results_copy / "sequences").glob("*.parquet"))[0]
    rows = len(pd.read_parquet(partition))
    damage(partition)
    (results_copy / "results.parquet").unlink()
    (results_copy / "results.csv").write_text("not a table\n")
    assert main(["run", "--scene", "free-boundary", "--formulation", "vi,mixed", "--solver",
                 "active-set", "--max-dofs", "300", "--out", str(results_copy)]) == 0
    err = capsys.readouterr().err
    assert "set aside as" in err and "Traceback" not in err
    assert (partition.parent / (partition.name + ".damaged")).exists()
    assert len(pd.read_parquet(partition)) == rows  # its sequence was run again


def test_tables_are_trusted_by_checksum_not_by_counts(results_copy, capsys):
    partition = sorted((results_copy / "sequences").glob("*.parquet"))[0]
    frame = pd.read_parquet(partition)
    frame["energy"] = frame["energy"] * 2.0  # same rows, same keys, other numbers
    frame.to_parquet(partition, index=False)
    table = read_results(results_copy)
    key = frame["sequence_key"].iloc[0]
    assert np.allclose(table.loc[table["sequence_key"] == key, "energy"], frame["energy"],
                       rtol=1e-15)  # the partition's numbers, not the stale table's
    assert "holds other rows than the partitions" in capsys.readouterr().err


def test_a_damaged_level_artifact_is_named_and_left_out(results_copy, tmp_path, capsys):
    artifact = sorted((results_copy / "artifacts").rglob("*.npz"))[0]
    damage(artifact)
    assert main(["export", "--results", str(results_copy), "--out", str(tmp_path / "f")]) == 0
    err = capsys.readouterr().err
    assert f"{artifact} is unreadable" in err and "Traceback" not in err


def test_diff_against_a_folder_of_another_schema_is_refused(results_copy, tmp_path, capsys):
    other = tmp_path / "other"
    other.mkdir()
    pd.DataFrame({"scene": ["paper"], "level": [0]}).to_parquet(other / "results.parquet")
    assert main(["diff", str(results_copy), str(other)]) == 2
    err = capsys.readouterr().err
    assert "of another schema" in err and "sequence_key" in err and "Traceback" not in err


@pytest.mark.parametrize("text", ["(" * 10000 + "x" + ")" * 10000, "-" * 5000 + "x",
                                  "+".join(["x"] * 1000), "x" * 100000])
def test_deeply_nested_expressions_are_refused_in_one_line(text):
    with pytest.raises(ExpressionError, match="too (long|deeply nested)"):
        Expression(text, where="gap")


def write_mesh(path, points, cells) -> str:
    meshio.write(path, meshio.Mesh(points, cells), file_format="gmsh22", binary=False)
    return str(path)


SQUARE = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]])


@pytest.mark.parametrize("points, cells, message", [
    (SQUARE, [("quad", np.array([[0, 1, 2, 3]]))], "holds no triangles"),
    (SQUARE, [("triangle", np.array([[0, 1, 2]])), ("quad", np.array([[0, 1, 2, 3]]))],
     "cells of type quad"),
    (SQUARE + np.array([0, 0, 1.0]) * SQUARE[:, :1], [("triangle", np.array([[0, 1, 2]]))],
     "is not a 2D mesh"),
    (SQUARE, [("triangle", np.array([[0, 1, 2], [0, 2, 2]]))], "degenerate"),
    (SQUARE, [("triangle", np.array([[0, 1, 2]])), ("line", np.array([[2, 3]]))],
     "nodes of no triangle"),
])
def test_mesh_files_are_read_exactly_or_refused(tmp_path, points, cells, message):
    path = write_mesh(tmp_path / "m.msh", points, cells)
    with pytest.raises(SceneError, match=message):
        read_mesh_file(path)


class SilentServer:
    """A port that accepts connections and never answers (or answers in HTTP)."""

    def __init__(self, reply: bytes = b""):
        self.socket = socket.create_server(("127.0.0.1", 0))
        self.address = f"tcp://127.0.0.1:{self.socket.getsockname()[1]}"
        self.reply, self.open = reply, []
        threading.Thread(target=self.serve, daemon=True).start()

    def serve(self):
        while True:
            try:
                connection, _ = self.socket.accept()
            except OSError:
                return
            if self.reply:
                connection.sendall(self.reply)
            self.open.append(connection)


@pytest.mark.parametrize("reply", [b"", b"HTTP/1.0 200 OK\r\n\r\nhello"])
def test_a_port_that_is_not_a_dask_scheduler_is_refused_in_time(reply):
    server = SilentServer(reply)
    try:
        with pytest.raises(SchedulerError, match="no Dask scheduler answered"):
            check_scheduler(server.address, timeout=1.0)
    finally:
        server.socket.close()

"""Field output: the files read back with meshio carry the run's own arrays."""

import subprocess
import sys

import meshio
import numpy as np
import pytest

from bench.cli import main
from bench.measure.discretisation_error import exact_errors
from bench.sequence.loop import LoopConfig, run_sequence
from estimators import get_estimator
from formulations.elasticity import von_mises
from scenes import get_scene


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    out = tmp_path_factory.mktemp("results")
    assert main(["run", "--scene", "free-boundary", "--formulation", "mixed,nitsche",
                 "--solver", "active-set", "--strategy", "uniform", "--max-dofs", "600",
                 "--out", str(out)]) == 0
    return out


@pytest.mark.parametrize("fmt", ["vtu", "xdmf"])
def test_fields_read_back_equal_the_runs_own(results, tmp_path, fmt):
    assert main(["export", "--results", str(results), "--format", fmt,
                 "--out", str(tmp_path)]) == 0
    body = meshio.read(tmp_path / f"free-boundary-nitsche-active-set-residual-uniform-1.{fmt}")
    contact = meshio.read(
        tmp_path / f"free-boundary-nitsche-active-set-residual-uniform-1-contact.{fmt}")
    # the same last level recomputed independently of the artifact (deterministic solve)
    scene = get_scene("free-boundary")
    last = list(run_sequence(scene, "nitsche", "active-set", "residual",
                             LoopConfig(strategy="uniform", max_dofs=600)))[-1]
    sol = last.solution
    mesh = sol.elasticity.mesh
    # written as float64 and read back: equal to round-off of the solve (1e-12 relative)
    assert np.allclose(body.points[:, :2], mesh.p.T, rtol=0, atol=1e-15)
    u = sol.elasticity.nodal(sol.u).T
    assert np.allclose(body.point_data["displacement"][:, :2], u, rtol=1e-10,
                       atol=1e-12 * np.abs(u).max())
    stress = sol.elasticity.element_stress(sol.u)
    tensor = body.cell_data["stress"][0].reshape(-1, 3, 3)
    scale = np.abs(stress).max()
    assert np.allclose(tensor[:, 0, 0], stress[0], atol=1e-10 * scale)
    assert np.allclose(tensor[:, 0, 1], stress[2], atol=1e-10 * scale)
    assert np.allclose(body.cell_data["von_mises"][0], von_mises(stress), atol=1e-10 * scale)
    indicators = get_estimator("residual")(scene, sol).indicators
    assert np.allclose(body.cell_data["indicator"][0], indicators, rtol=1e-8)
    # the error density sums to the squared exact energy-norm error
    density = body.cell_data["error_density"][0]
    assert density.sum() == pytest.approx(exact_errors(scene, sol).energy_error ** 2, rel=1e-10)
    # Gamma_C: one line per contact facet, lambda_h >= 0 and the gap at its ends
    assert len(contact.cells_dict["line"]) == sol.trace.size
    ends = sol.pressure(np.array([0.0, 1.0]))
    assert np.allclose(contact.point_data["lambda_h"],
                       np.concatenate([ends[:, 0], ends[:, 1]]), rtol=1e-10, atol=1e-9)
    assert np.isfinite(contact.point_data["gap"]).all()


def test_export_without_artifacts_is_refused(tmp_path, capsys):
    assert main(["export", "--results", str(tmp_path)]) == 2
    assert "holds no artifacts/" in capsys.readouterr().err


def test_the_console_command_runs_the_same_commands():
    # installed by pip (project.scripts): the same main as python -m bench
    done = subprocess.run([sys.executable, "-c", "from importlib.metadata import entry_points;"
                           "print([e.value for e in entry_points(group='console_scripts')"
                           " if e.name == 'signorini-bench'])"], capture_output=True, text=True)
    assert "bench.cli:main" in done.stdout, done.stdout + done.stderr


@pytest.mark.parametrize("fmt", ["vtu", "xdmf"])
def test_every_level_is_written_and_collected_in_one_series(results, tmp_path, fmt):
    import xml.etree.ElementTree as ET

    assert main(["export", "--results", str(results), "--format", fmt, "--levels", "all",
                 "--out", str(tmp_path)]) == 0
    stem = "free-boundary-mixed-active-set-residual-uniform-1"
    sequence = list(run_sequence(get_scene("free-boundary"), "mixed", "active-set", "residual",
                                 LoopConfig(strategy="uniform", max_dofs=600)))
    files = sorted((tmp_path / stem).glob(f"level-*[0-9].{fmt}"))
    assert len(files) == len(sequence) >= 3
    for file, level in zip(files, sequence, strict=True):
        mesh = level.solution.elasticity.mesh
        body = meshio.read(file)
        assert body.points.shape[0] == mesh.p.shape[1]  # each level its own mesh
        u = level.solution.elasticity.nodal(level.solution.u).T
        # the same deterministic solve, written as float64: round-off of the solve
        assert np.allclose(body.point_data["displacement"][:, :2], u, rtol=1e-10,
                           atol=1e-12 * np.abs(u).max())
    series = tmp_path / f"{stem}.{'pvd' if fmt == 'vtu' else 'xdmf'}"
    root = ET.parse(series).getroot()
    if fmt == "vtu":
        entries = root.findall("Collection/DataSet")
        assert [e.get("timestep") for e in entries] == [str(k) for k in range(len(files))]
        assert all((tmp_path / e.get("file")).is_file() for e in entries)
    else:
        grids = root.findall("Domain/Grid/Grid")
        assert [g.find("Time").get("Value") for g in grids] == [str(k)
                                                                for k in range(len(files))]
        for item in root.iter("DataItem"):  # every heavy-data path resolves from the series
            assert (tmp_path / item.text.strip().split(":")[0]).is_file()
    assert (tmp_path / f"{stem}-contact{series.suffix}").is_file()


def test_a_field_the_run_did_not_compute_is_left_out_not_written_as_nan():
    from bench.export.fields import body_mesh

    mesh = get_scene("paper").mesh
    n = mesh.t.shape[1]
    data = {"p": mesh.p, "t": mesh.t, "u": np.zeros_like(mesh.p),
            "stress": np.ones((3, n)), "von_mises": np.ones(n), "indicators": np.ones(n),
            "error_density": np.full(n, np.nan)}  # a scene without truth
    body = body_mesh(data)
    assert "error_density" not in body.cell_data
    assert {"stress", "von_mises", "indicator"} <= set(body.cell_data)

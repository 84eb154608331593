"""The memory route of a level once its dense Schur block is known (bench.sequence.memory,
docs/theory.md, sections 7 and 16)."""

import pytest

import bench.sequence.memory as memory_module
from bench.sequence.loop import LoopConfig, run_sequence
from bench.sequence.memory import MemoryRoute, dense_block_route
from formulations import formulation_names, get_formulation, solve
from formulations.discretisation import dense_block_size
from formulations.solvers import FAST_SOLVER, REFERENCE_SOLVER, backends
from scenes import get_scene

CONDENSING = [b for b in backends.available_backends() if backends.condenses(b)]
HAS_AMG = "amg" in backends.available_backends()


@pytest.mark.parametrize("scene_name", ["paper", "stick-slip"])  # without and with friction
@pytest.mark.parametrize("formulation", formulation_names())
@pytest.mark.skipif(not CONDENSING, reason="no condensing back-end")
def test_the_declared_block_is_the_one_the_back_end_allocates(formulation, scene_name,
                                                              monkeypatch):
    allocated, real = [], backends.check_dense_block
    monkeypatch.setattr(backends, "check_dense_block",
                        lambda size: (allocated.append(size), real(size))[1])
    scene = get_scene(scene_name)
    disc = get_formulation(formulation)(scene, scene.mesh.refined(3))
    declared = dense_block_size(disc, FAST_SOLVER, CONDENSING[0])
    assert solve(disc, FAST_SOLVER, backend=CONDENSING[0]).status == "ok"
    assert allocated == [declared] and declared > 0
    # no dense block: the reference uses no back-end, an iterative back-end condenses nothing
    assert dense_block_size(disc, REFERENCE_SOLVER, CONDENSING[0]) == 0
    if HAS_AMG:
        assert dense_block_size(disc, FAST_SOLVER, "amg") == 0


def fits(ndofs, solver, backend, order=1, dim=2):  # every level's line: 0.1 GiB
    return 0.1


@pytest.mark.skipif(not (CONDENSING and HAS_AMG), reason="needs pardiso/cholmod and amg")
def test_a_block_that_does_not_fit_beside_the_level_moves_it_to_the_iterative_back_end(
        monkeypatch):
    monkeypatch.setattr(memory_module, "predict_peak_gib", fits)
    direct, admitted = CONDENSING[0], MemoryRoute(limit_gib=1.0)
    # 3 copies of 6000^2 doubles: 0.80 GiB, 0.90 with the line; 7000^2: 1.10, 1.20
    assert dense_block_route(admitted, 3, 10**5, 6000, FAST_SOLVER, direct) == admitted
    moved = dense_block_route(admitted, 3, 10**5, 7000, FAST_SOLVER, direct)
    assert moved.backend == "amg" and moved.limit_gib == 1.0 and moved.refusal is None
    assert moved.note == (f"memory: level 3's dense Schur block of 7000 contact DOFs needs "
                          f"~1.10 GiB ({direct}), ~1.20 GiB with the rest, 1.00 available; "
                          "solved by amg instead")
    # already rerouted, refused, or no iterative back-end that fits: left as it was
    rerouted = MemoryRoute("amg", "memory: ...", None, 1.0)
    assert dense_block_route(rerouted, 3, 10**5, 7000, FAST_SOLVER, direct) == rerouted
    refused = MemoryRoute(refusal="memory: ...", limit_gib=1.0)
    assert dense_block_route(refused, 3, 10**5, 7000, FAST_SOLVER, direct) == refused
    monkeypatch.setattr(memory_module, "iterative_route", lambda *args: None)
    assert dense_block_route(admitted, 3, 10**5, 7000, FAST_SOLVER, direct) == admitted


@pytest.mark.skipif(not (CONDENSING and HAS_AMG), reason="needs pardiso/cholmod and amg")
def test_the_sequence_solves_a_level_whose_block_does_not_fit_on_the_iterative_back_end(
        monkeypatch):
    """vi on paper: 66 contact DOFs at 2112 DOFs, 130 at 8320 (the test above checks them
    against the back-end). With 1e5 copies the first block needs 3.2 GiB, the second 12.6."""
    monkeypatch.setattr(memory_module, "predict_peak_gib", fits)
    monkeypatch.setattr(memory_module, "DENSE_COPIES", 10**5)
    monkeypatch.setattr(memory_module, "available_gib", lambda: 8.0)
    rows = [r.row for r in run_sequence(get_scene("paper"), "vi", FAST_SOLVER, "residual",
                                        LoopConfig(strategy="uniform", max_dofs=8400,
                                                   backend=CONDENSING[0]))]
    assert [r.status for r in rows] == ["ok"] * 5 and rows[-1].ndofs == 8320
    assert [r.backend for r in rows] == [CONDENSING[0]] * 4 + ["amg"]
    assert "dense Schur block of 130 contact DOFs" in rows[-1].reason
    assert "solved by amg instead" in rows[-1].reason

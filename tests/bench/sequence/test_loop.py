"""End-to-end refinement sequences on the paper scene."""

import numpy as np
import pandas as pd
import pytest

from bench.matrix import RunConfig, run
from bench.matrix.store import ResultStore
from bench.measure.contact import SOLVED_STATUSES as SOLVED
from bench.sequence.loop import LoopConfig, run_sequence
from bench.sequence.rows import COLUMNS
from scenes import get_scene

REQUIRED = ("scene formulation solver estimator strategy level ndofs h_max h_min max_h_over_H "
            "energy contact_force active_constraints eta eta_0 eta_geometric eta_complementarity "
            "violation complementarity stationarity iterations t_assemble t_solve t_estimate "
            "t_refine status reason commit versions machine").split()


@pytest.fixture(scope="module")
def adaptive_rows():
    config = LoopConfig(strategy="adaptive", max_dofs=4000)
    return [r.row for r in run_sequence(get_scene("paper"), "mixed", "reference", "residual",
                                        config)]


def test_required_columns_exist():
    assert set(REQUIRED) <= set(COLUMNS)


def test_paper_adaptive_run_is_ok_and_settles(adaptive_rows):
    rows = adaptive_rows
    assert all(r.status in SOLVED for r in rows), [(r.level, r.reason) for r in rows]
    assert 2000 < rows[-1].ndofs <= 4000
    # h/H is a ratio of computed lengths: 1/2 holds to a few ulps (the builder allows 1e-12)
    assert all(r.max_h_over_H <= 0.5 + 1e-12 for r in rows)
    energy = np.array([r.energy for r in rows])
    force = np.array([r.contact_force for r in rows])
    print("levels", [r.ndofs for r in rows], "energy", energy, "contact force", force)
    # the contact-driven energy converges like eta^2; at a few thousand DOFs eta^2 / energy is
    # ~5 %, so successive energies and forces must already agree to a few percent
    assert abs(energy[-1] - energy[-2]) / energy[-1] < 0.02
    assert abs(force[-1] - force[-2]) / force[-1] < 0.02
    # and eta decreases overall as the mesh is refined
    assert rows[-1].eta < 0.25 * rows[0].eta


def test_adaptive_beats_uniform_at_equal_cost(adaptive_rows):
    uniform = [r.row for r in run_sequence(get_scene("paper"), "mixed", "reference", "residual",
                                           LoopConfig(strategy="uniform", max_dofs=2200))]
    u_last = uniform[-1]
    a_comparable = min(adaptive_rows, key=lambda r: abs(r.ndofs - u_last.ndofs))
    assert a_comparable.eta < u_last.eta


def test_store_keeps_finished_rows_when_a_run_breaks(tmp_path, monkeypatch):
    import bench.sequence.loop as loop_module

    calls = {"n": 0}
    real = loop_module.solve

    def flaky(disc, solver, **options):
        calls["n"] += 1
        if calls["n"] == 3:
            raise RuntimeError("simulated crash in the third solve")
        return real(disc, solver, **options)

    monkeypatch.setattr(loop_module, "solve", flaky)
    # the untimed warm-up (bench.matrix.task.warm_up) would take the first solves
    monkeypatch.setattr("bench.matrix.task.warm_up", lambda scene, spec: None)
    out = tmp_path / "out"
    rows = run(RunConfig(solvers=("reference",), strategies=("uniform",), max_dofs=5000,
                         out=str(out))).rows
    assert [r.status in SOLVED for r in rows] == [True, True, False]
    assert rows[-1].status == "failed"
    assert "simulated crash" in rows[-1].reason
    for frame in (pd.read_parquet(out / "results.parquet"), pd.read_csv(out / "results.csv")):
        assert list(frame["status"]) == [r.status for r in rows]
        assert set(REQUIRED) <= set(frame.columns)


@pytest.mark.parametrize("changes, message", [
    (dict(strategy="random"), "strategy='random' is not one of uniform, adaptive"),
    (dict(max_dofs=0), "max_dofs=0 is not a positive integer"),
    (dict(theta=2.0), r"theta=2.0 is not in \(0, 1\]"),
])
def test_loop_config_validation(changes, message):
    with pytest.raises(ValueError, match=message):
        LoopConfig(**changes)


def test_nested_iteration_keeps_active_set_iterations_flat():
    # the point of nested iteration: <= 3 active-set iterations per level after the first when
    # each level starts from the previous level's contact zone; a cold start needs more
    def iterations(nested):
        config = LoopConfig(strategy="adaptive", max_dofs=15000, nested=nested)
        return [r.row for r in run_sequence(get_scene("paper"), "mixed", "active-set",
                                            "residual", config)]
    warm, cold = iterations(True), iterations(False)
    assert all(r.status in SOLVED for r in warm + cold)
    assert [r.warm_started for r in warm] == [False] + [True] * (len(warm) - 1)
    assert max(r.iterations for r in warm[1:]) <= 3, [r.iterations for r in warm]
    assert sum(r.iterations for r in warm) < sum(r.iterations for r in cold)
    # the warm start changes the path, not the answer
    assert [r.energy for r in warm] == pytest.approx([r.energy for r in cold], rel=1e-10)


def test_store_adds_new_columns_to_results_of_an_older_version(tmp_path):
    old = pd.DataFrame({"scene": ["paper"], "level": [0], "energy": [1.0]})
    old.to_parquet(tmp_path / "results.parquet")
    old.to_csv(tmp_path / "results.csv", index=False)
    store = ResultStore(tmp_path)
    # taken over as a partition with every column, kept in the consolidated tables
    assert list(store.table().columns) == COLUMNS and len(store.table()) == 1
    store.consolidate()
    table = pd.read_csv(tmp_path / "results.csv")
    assert list(table.columns) == COLUMNS and table["energy"].tolist() == [1.0]


def test_every_row_carries_the_stability_diagnostics(tmp_path):
    config = LoopConfig(strategy="uniform", max_dofs=9000)
    rows = {f: [r.row for r in run_sequence(get_scene("paper"), f, "active-set", "residual",
                                            config)] for f in ("mixed", "vi")}
    for formulation, sequence in rows.items():
        for row in sequence[1:]:  # level 0 has no contact on the paper scene
            assert row.status in SOLVED and not row.cycled and row.safeguard == ""
            changes = [int(c) for c in row.active_set_changes.split(",")]
            assert changes[-1] == 0 and len(changes) == row.iterations
            # a condition number is >= 1; the estimate is a product of two computed norms,
            # each exact to a few ulps, hence the 1e-12 relative slack
            assert row.condition_estimate >= 1.0 - 1e-12
            # one hump of pressure: TV / (2 max) = 1 (up to the P0 staircase's overshoot); TV
            # is a sum of ~10^3 differences, each rounded to an ulp of the peak, so it can fall
            # below 2 max by ~10^3 eps ~ 2e-13 (0.9999999999999999 was seen): 1e-12 slack
            assert 1.0 - 1e-12 <= row.pressure_oscillation < 1.05
            assert np.isnan(row.inf_sup) == (formulation != "mixed")
    # the mixed method at h/H = 1/2 is inf-sup stable: beta_h bounded below, settling (the
    # hard case mixed-h/H measures the same against h/H = 1, where it decays like h)
    beta = np.array([r.inf_sup for r in rows["mixed"]])
    assert beta.min() > 0.5 and abs(beta[-1] - beta[-2]) < 0.02
    # every column survives the store
    store = ResultStore(tmp_path)
    for row in rows["mixed"]:
        store.append(row)
    store.consolidate()  # what the end of a sequence does
    table = pd.read_parquet(store.parquet)
    assert table["active_set_changes"].iloc[-1] == rows["mixed"][-1].active_set_changes
    assert table["inf_sup"].notna().all()

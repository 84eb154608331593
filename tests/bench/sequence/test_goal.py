"""Goal-driven sequences: every row of a run with a goal carries the quantity's columns, the
goal strategy refines by the dual-weighted indicators (another mesh than the energy's), and a
goal the estimator cannot serve is refused before a solve or recorded in the rows."""

import math

import pytest

from bench.matrix.task import why_skipped
from bench.sequence.loop import LoopConfig, run_sequence
from bench.truth.kinds import ExactTruth
from scenes import get_scene

SCENE = get_scene("free-boundary", align_jump=1)


def rows(strategy: str, goal: str | None = "contact-force", order: int = 1,
         max_dofs: int = 1500):
    config = LoopConfig(strategy=strategy, goal=goal, order=order, max_dofs=max_dofs)
    return [r.row for r in run_sequence(SCENE, "mixed", "active-set", "residual", config,
                                        truth=ExactTruth(SCENE))]


@pytest.fixture(scope="module")
def goal_rows():
    return rows("goal", goal=None)


def test_the_goal_strategy_measures_the_contact_force_by_default(goal_rows):
    assert {r.goal for r in goal_rows} == {"contact-force"}
    last = goal_rows[-1]
    # the true error is the closed form's force minus the computed one, exactly as stored
    assert last.qoi_error == pytest.approx(last.qoi_true - last.qoi, rel=0, abs=1e-15)
    assert last.qoi_exact == last.qoi_true and last.goal_status == ""
    assert last.qoi_effectivity == pytest.approx(last.qoi_estimate / last.qoi_error)
    assert last.dual_dofs > last.ndofs and last.t_goal > 0


def test_goal_driven_and_energy_driven_meshes_differ(goal_rows):
    energy = rows("adaptive")
    assert all(r.goal == "contact-force" and math.isfinite(r.qoi_estimate) for r in energy)
    pairs = list(zip((r.ndofs for r in goal_rows), (r.ndofs for r in energy), strict=False))
    assert pairs[0][0] == pairs[0][1] and any(a != b for a, b in pairs[1:])


def test_a_run_without_a_goal_has_no_qoi_columns():
    plain = rows("adaptive", goal=None, max_dofs=300)
    assert all(r.goal == "" and math.isnan(r.qoi) for r in plain)


def test_a_measured_goal_without_a_dual_space_says_why_in_its_rows():
    p3 = rows("uniform", order=3, max_dofs=400)
    assert all(math.isfinite(r.qoi) and math.isnan(r.qoi_estimate) for r in p3)
    assert all("P4" in r.goal_status for r in p3)


def test_a_goal_strategy_the_estimator_cannot_serve_is_skipped():
    why = why_skipped(SCENE, "mixed", "active-set", "residual", order=3, strategy="goal")
    assert why is not None and "P4" in why
    why = why_skipped(get_scene("paper"), "mixed", "active-set", "residual",
                      strategy="adaptive", goal="peak-pressure")
    assert "no peak" in why


def test_an_unknown_goal_is_refused_with_the_names():
    with pytest.raises(ValueError, match="goal='stress' is not one of contact-force"):
        LoopConfig(goal="stress")


def test_a_guaranteed_energy_bound_gives_the_force_an_interval_that_holds():
    config = LoopConfig(strategy="adaptive", goal="contact-force", max_dofs=800)
    levels = [r.row for r in run_sequence(SCENE, "vi", "active-set", "equilibrated", config,
                                          truth=ExactTruth(SCENE))]
    assert all(r.qoi_guaranteed and r.qoi_interval_holds for r in levels)
    assert all(r.qoi_lower <= r.qoi_true <= r.qoi_upper for r in levels)
    plain = rows("adaptive", max_dofs=300)  # residual: no guaranteed bound, no interval
    assert not any(r.qoi_guaranteed for r in plain) and all(math.isnan(r.qoi_lower)
                                                             for r in plain)

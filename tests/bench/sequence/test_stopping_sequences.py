"""Adaptive stopping in the refinement loop against exact solutions: eta_total bounds the
error of the iterate the solver returns, on every level and on intermediate iterates
(docs/theory.md, section 18)."""

from __future__ import annotations

import numpy as np
import pytest

from bench.measure.contact import SOLVED_STATUSES as SOLVED
from bench.sequence.loop import LoopConfig, run_sequence
from bench.truth import truth_for
from estimators.base import estimator_on
from estimators.guaranteed.constants import domain_constants
from formulations import get_formulation
from formulations.base import QPSolution
from formulations.cells import family_for
from formulations.hat_loads import load_norm
from formulations.kkt import qp_residuals
from formulations.solvers.projected import solve_projected
from formulations.solvers.stopping import ADAPTIVE, Stopping
from scenes import get_scene

# eta_total is a proved bound: it may meet the error only to round-off (1e-10 relative)
ROUND_OFF = 1 + 1e-10


def rows(scene, formulation, config, estimator="equilibrated"):
    return [r.row for r in run_sequence(scene, formulation, "active-set", estimator, config,
                                        truth=truth_for(scene, None))]


@pytest.mark.parametrize("formulation", ["vi", "mixed"])
def test_eta_total_bounds_the_error_of_every_adaptively_stopped_level(formulation):
    config = LoopConfig(strategy="adaptive", max_dofs=6000, backend="amg", stopping="adaptive")
    result = rows(get_scene("free-boundary"), formulation, config)
    assert all(r.status in SOLVED for r in result), [r.reason for r in result]
    assert any(r.stopped_early for r in result)  # the rule acted on some level
    for r in result:
        assert r.eta_total * ROUND_OFF >= r.energy_error, (r.level, r.eta_total, r.energy_error)
        assert np.isfinite(r.eta_alg) and np.isfinite(r.eta_lin) and r.eta_disc <= r.eta_total


def test_eta_total_bounds_the_error_in_3d():
    config = LoopConfig(strategy="uniform", max_dofs=3000, backend="amg", stopping="adaptive")
    result = rows(get_scene("free-boundary-3d"), "vi", config)
    assert all(r.status in SOLVED for r in result), [r.reason for r in result]
    for r in result:
        assert r.eta_total * ROUND_OFF >= r.energy_error, (r.level, r.eta_total, r.energy_error)


INTERMEDIATE = [("free-boundary", f) for f in ("vi", "mixed", "penalty", "nitsche")] + [
    pytest.param("free-boundary-3d", f, marks=pytest.mark.slow) for f in ("vi", "mixed")]


@pytest.mark.parametrize("scene_name, formulation", INTERMEDIATE)
def test_the_bound_holds_on_every_intermediate_iterate(scene_name, formulation):
    """The projected active-set iteration on the formulation's QP (Nitsche: its convex form,
    theta = 1) from an empty active set, stopped after k = 1, 2, ... sets, each solve loose:
    the guaranteed bound of each iterate (with its residuals) is above its error."""
    scene = get_scene(scene_name)
    family = family_for("tri", scene.dim)
    mesh = scene.mesh.refined(4) if scene.dim == 2 else family.starting_mesh(scene).refined(1)
    disc = get_formulation(formulation)(scene, mesh, order=1)  # Nitsche: theta = 1
    qp, truth = disc.qp, truth_for(scene, None)
    estimate = estimator_on("equilibrated", family.name)
    norm = load_norm(disc.elasticity, domain_constants(scene).friedrichs)
    checked = 0
    for k in range(1, 6):
        u, lam, iterations, status, reason, diagnostics = solve_projected(
            qp, np.zeros(qp.m, dtype=bool), k, "amg",  # from nothing in contact
            Stopping(ADAPTIVE, norm, expected_disc=1.0, gamma_alg=0.5, gamma_lin=1e-12))
        answer = QPSolution(u, lam, "ok", "", iterations, 0.0, "active-set", "amg",
                            diagnostics)
        solution = disc.recover(answer, qp_residuals(qp, u, lam), "ok", "")
        error = truth.errors(solution).energy_error
        eta = estimate(scene, solution).eta
        assert eta * ROUND_OFF >= error, (k, eta, error)
        checked += 1
        if status == "ok":
            break
    assert checked >= 2  # at least one iterate before the last


def test_fixed_rows_carry_the_components_and_the_report_prices_the_rule(tmp_path):
    """With the fixed tolerances eta_alg is round-off and eta_total is eta; a results folder
    with both rules gets the report's figure and its work-saved table."""
    from bench.report import write_report
    from bench.sequence.rows import COLUMNS

    scene = get_scene("free-boundary")
    tables = []
    for rule in ("fixed", "adaptive"):
        config = LoopConfig(strategy="adaptive", max_dofs=3000, backend="amg", stopping=rule)
        result = rows(scene, "vi", config)
        assert {r.stopping for r in result} == {rule}
        tables += [r.as_dict() for r in result]
        if rule == "fixed":
            for r in result:  # RTOL 1e-10 leaves eta_alg ~1e-8 of eta (measured): round-off
                assert r.eta_alg < 1e-6 * r.eta_total and r.eta_total == r.eta
    import pandas as pd
    frame = pd.DataFrame(tables, columns=COLUMNS)
    readme = write_report(frame, tmp_path).read_text()
    assert "### When the solvers stop" in readme and "figures/stopping.png" in readme
    assert "Krylov saved" in readme


def test_adaptive_stopping_is_refused_on_quadrilaterals():
    with pytest.raises(ValueError, match="stopping='adaptive' is measured on triangles and "
                                         "tetrahedra only"):
        LoopConfig(cell="quad", stopping="adaptive")

"""Friction in the nodal VI: the box iteration, its bounded least-squares safeguard, the
Coulomb fixed point and its verdict, and the refusals of the formulations without it."""

from dataclasses import replace

import numpy as np
import pytest

from bench.measure.difference import solution_difference
from formulations import get_formulation, solve
from formulations.cells import family_for
from formulations.kkt import RESIDUAL_TOLERANCE, qp_residuals
from formulations.registry import FORMULATIONS
from formulations.solvers.backends import available_backends, iterative
from formulations.solvers.box import (
    AT_LOWER,
    AT_UPPER,
    FREE,
    box_bvls,
    box_pdas,
    initial_state,
)
from scenes import get_scene
from scenes.friction import friction_law


def test_box_pdas_solves_a_diagonal_box_qp_exactly():
    # S = diag(d): lam_i = clip(r_i / d_i, lower_i, upper_i) is the unique minimiser
    d = np.array([1.0, 2.0, 4.0, 0.5, 1.0])
    r = np.array([3.0, -3.0, 2.0, -0.1, 0.2])
    lower = np.array([0.0, -1.0, -0.25, -1.0, 0.0])
    upper = np.array([np.inf, 1.0, 0.25, 1.0, 0.0])  # the last is pinned at 0
    result = box_pdas(np.diag(d), r, lower, upper, initial_state(r, lower, upper))
    assert result.status == "ok"
    # the free entries come from an LU solve of a diagonal block: exact up to one rounding
    assert result.lam == pytest.approx(np.clip(r / d, lower, upper), rel=1e-15, abs=0)
    assert list(result.state) == [FREE, AT_LOWER, AT_UPPER, FREE, AT_LOWER]


def test_box_pdas_reports_a_cycle_instead_of_looping():
    S = np.array([[2.0, -1.9], [-1.9, 2.0]])
    r = np.array([1.0, -1.0])
    result = box_pdas(S, r, np.full(2, -0.1), np.full(2, 0.1),
                      np.array([AT_UPPER, AT_UPPER]), max_iter=1)
    assert result.status == "failed" and "still changing" in result.reason


def test_bounded_least_squares_solves_the_box_qps_where_the_iteration_cycles():
    rng = np.random.default_rng(0)
    cycling = 0
    for _ in range(2000):
        A = rng.normal(size=(6, 6))
        S, r = A @ A.T + 0.01 * np.eye(6), 3 * rng.normal(size=6)
        lower, upper = -rng.uniform(0, 1, 6), rng.uniform(0, 1, 6)
        if box_pdas(S, r, lower, upper, initial_state(r, lower, upper)).status == "ok":
            continue
        cycling += 1
        result = box_bvls(S, r, lower, upper)
        assert result.status == "ok" and result.safeguard == "bounded least squares"
        # the KKT conditions of the box QP: lam is its own projected gradient step; the
        # confirming PDAS iteration leaves round-off of an SPD solve of size 6
        step = np.clip(result.lam - (S @ result.lam - r), lower, upper)
        assert np.abs(result.lam - step).max() < 1e-12 * max(1.0, np.abs(r).max())
    assert cycling > 10  # the plain iteration does cycle on such problems (measured 30 of 2000)



@pytest.mark.parametrize("backend", available_backends())
def test_every_backend_gives_the_same_tresca_answer(backend):
    scene = get_scene("stick-slip")
    disc = get_formulation("vi")(scene, scene.mesh.refined(2))
    answer, direct = solve(disc, "active-set", backend=backend), solve(disc, "active-set",
                                                                       backend="splu")
    assert answer.status == "ok" and answer.backend == backend
    energy, _ = solution_difference(disc, answer, direct)
    # a direct back-end: round-off; amg: its Krylov stopping rule, 1e-10 relative
    assert energy < (1e-8 if iterative(backend) else 1e-12)


def test_the_fixed_point_is_relaxed_where_it_cycles_and_fails_where_it_is_too_slow():
    mesh = get_scene("paper").mesh.refined(3)
    # mu = 10: the plain fixed point repeats a change of 3.5e-2; halving the step converges
    scene = get_scene("paper", friction="coulomb", mu=10.0)
    answer = solve(get_formulation("vi")(scene, mesh), "active-set")
    assert answer.status == "ok" and max(vars(answer.residuals).values()) < 1e-10
    scene = get_scene("paper", friction="coulomb", mu=30.0)
    answer = solve(get_formulation("vi")(scene, mesh), "active-set")
    assert answer.status == "failed"
    assert "Coulomb fixed point not converged after 100 Tresca steps" in answer.reason
    assert "mu=30 too large" in answer.reason


def test_the_friction_residuals_catch_a_wrong_tangential_reaction():
    scene = get_scene("stick-slip")
    disc = get_formulation("vi")(scene, scene.mesh.refined(2))
    fast = solve(disc, "active-set")
    qp, u, lam_n = disc.qp, fast.u[disc.elasticity.free], fast.multipliers
    lam_t = fast.friction.tangential_reactions
    assert max(vars(qp_residuals(qp, u, lam_n, lam_t)).values()) < 1e-10
    beyond = qp_residuals(qp, u, lam_n, 2 * lam_t)  # over the bound, out of equilibrium
    # a slipping node's 2 |lambda_t| exceeds its bound b by b: half of the scale max |2 lambda_t|
    assert beyond.dual_violation == pytest.approx(0.5, rel=1e-12)
    assert beyond.stationarity > 1e-3
    reversed_slip = qp_residuals(qp, u, lam_n, -lam_t)  # pushes along the slip
    # 2 sum b |T u| relative to the energy: small slips, but far above what an answer called
    # ok may leave (RESIDUAL_TOLERANCE)
    assert reversed_slip.complementarity > 10 * RESIDUAL_TOLERANCE


def test_the_nodes_stick_slip_and_separate_where_the_exact_solution_does():
    scene = get_scene("stick-slip")
    disc = get_formulation("vi")(scene, scene.mesh.refined(4))
    state = solve(disc, "active-set").friction
    s = state.coordinate
    # away from the exact ends b = 0.2, a = 0.4 by 3.2, 2.2 and 1.3 mesh sizes h = 1/32 (the
    # traction reaches its bound quadratically at b, so the discrete end lies within a few h)
    assert set(state.state[np.abs(s) < 0.2 - 0.1]) == {"stick"}
    assert set(state.state[(np.abs(s) > 0.2 + 0.07) & (np.abs(s) < 0.4 - 0.04)]) == {"slip"}
    assert set(state.state[np.abs(s) > 0.4 + 0.04]) == {"separated"}


@pytest.mark.parametrize("formulation", FORMULATIONS.names())
def test_a_formulation_without_friction_refuses_the_scene(formulation):
    scene = get_scene("stick-slip")
    why = FORMULATIONS.why_not(formulation, scene=scene)
    if FORMULATIONS.meta(formulation, "friction", False):
        assert why is None
        assert FORMULATIONS.why_not(formulation, scene=get_scene("paper")) is None
    else:
        assert why == (f"formulation {formulation!r} does not model friction (the scene's "
                       "law is tresca)")
    # in 3D the bound is a disc per point: the tetrahedra take it, and each formulation says
    # whether it models it there (register_formulation(..., friction=(2, 3)))
    solid = replace(get_scene("free-boundary-3d"), friction=friction_law("tresca",
                                                                         slip_bound=1.0))
    assert family_for("tri", 3).why_not(solid) is None
    why = FORMULATIONS.why_not(formulation, scene=solid)
    if 3 in FORMULATIONS.meta(formulation, "friction_dims", ()):
        assert why is None
    elif FORMULATIONS.meta(formulation, "friction", False):
        assert why == (f"formulation {formulation!r} does not model friction in 3D (the "
                       "scene's law is tresca)")

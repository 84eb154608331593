"""Friction in 3D on the nodal VI: the tangent frame, the disc QP's semismooth Newton solve,
and the fast solve of paper-3d with Tresca and Coulomb friction against the second-order-cone
reference (docs/theory.md, 17.3)."""

from dataclasses import replace

import cvxpy as cp
import numpy as np
import pytest

from bench.measure.contact import SOLVED_STATUSES as SOLVED
from bench.measure.difference import solution_difference
from bench.sequence.loop import LoopConfig, run_sequence
from estimators.base import ESTIMATORS
from formulations import get_formulation, solve
from formulations.contact.boundary import tangent_frame
from formulations.registry import FORMULATIONS
from formulations.solvers.disc import disc_ssn
from scenes import get_scene
from scenes.friction import friction_law


def test_the_tangent_frame_is_orthonormal_and_orthogonal_to_the_normal():
    normal = np.random.default_rng(0).normal(size=(3, 50))
    normal /= np.linalg.norm(normal, axis=0)
    normal[:, 0] = [0.0, 0.0, -1.0]  # a plane Gamma_C's normal
    first, second = tangent_frame(normal)
    for a, b in [(first, second), (first, normal), (second, normal)]:
        assert np.abs((a * b).sum(axis=0)).max() < 1e-15  # round-off of one cross product
    for t in (first, second):
        assert np.linalg.norm(t, axis=0) == pytest.approx(1.0, abs=1e-15)


def test_semismooth_newton_solves_random_disc_qps():
    rng = np.random.default_rng(1)
    for _ in range(20):
        m = 6
        A = rng.normal(size=(3 * m, 3 * m))
        S, r = A @ A.T + 0.05 * np.eye(3 * m), 3 * rng.normal(size=3 * m)
        bound = rng.uniform(0, 1, m)
        bound[0] = 0.0  # a node that slides freely
        result = disc_ssn(S, r, m, bound)
        assert result.status == "ok", result.reason
        lam = result.lam
        # the optimality condition, written here independently: lam is its own projected
        # gradient step (normal entries onto [0, inf), pairs onto their discs)
        z = lam - (S @ lam - r)
        pairs = z[m:].reshape(-1, 2)
        size = np.linalg.norm(pairs, axis=1)
        shrink = np.minimum(1.0, bound / np.where(size > 0, size, 1.0))
        step = np.concatenate([np.maximum(z[:m], 0.0), (pairs * shrink[:, None]).ravel()])
        assert np.abs(lam - step).max() < 1e-11 * max(1.0, np.abs(r).max())
        x = cp.Variable(3 * m)
        cp.Problem(cp.Minimize(0.5 * cp.quad_form(x, S) - r @ x),
                   [x[:m] >= 0, cp.SOC(cp.Constant(bound), cp.reshape(x[m:], (m, 2), order="C"),
                                       axis=1)]).solve(
            solver=cp.CLARABEL, tol_gap_abs=1e-10, tol_gap_rel=1e-10, tol_feas=1e-10)
        # and Clarabel's answer at 1e-10: agreement to its accuracy at the cones' apex
        # (measured <= 1.1e-6)
        assert np.abs(lam - x.value).max() < 1e-5 * max(1.0, np.abs(x.value).max())
        assert np.all(lam[:m] >= 0)
        assert np.all(np.linalg.norm(lam[m:].reshape(-1, 2), axis=1) <= bound * (1 + 1e-12))


@pytest.mark.parametrize("law", [friction_law("coulomb", mu=0.3),
                                 friction_law("tresca", slip_bound=35.0)])
def test_the_fast_3d_solve_is_exact_and_agrees_with_the_cone_reference(law):
    scene = replace(get_scene("paper-3d"), friction=law)
    disc = get_formulation("vi")(scene, scene.mesh.refined(1))
    assert disc.qp.friction.block == 2
    fast, reference = solve(disc, "active-set"), solve(disc, "reference")
    assert fast.status == "ok" and reference.status == "ok", (fast.reason, reference.reason)
    # the semismooth Newton iteration stops at round-off: every KKT residual, the discs' dual
    # violation and slip complementarity included, is tiny (measured <= 2e-13)
    assert max(vars(fast.residuals).values()) < 1e-10, fast.residuals
    energy, pressure = solution_difference(disc, fast, reference)
    shear = (np.abs(fast.friction.shear - reference.friction.shear).max()
             / np.abs(reference.friction.shear).max())
    # the interior-point cones converge slowly at their apex (the sticking nodes): measured
    # 1.4e-7 / 4.5e-7 in energy, 2e-7 in the pressure and 2e-5 / 3e-3 in the shear (a slip
    # direction fixed by slips of 4e-3 against u of 0.15) for Coulomb / Tresca
    assert energy < 2e-6 and pressure < 1e-5 and shear < 1e-2, (energy, pressure, shear)
    states = set(fast.friction.state)
    assert "slip" in states and "separated" in states


def test_a_3d_sequence_with_friction_runs_where_it_is_modelled():
    scene = get_scene("paper-3d", friction="coulomb", mu=0.3)
    assert "vi" in [f for f in FORMULATIONS.names() if FORMULATIONS.why_not(f, scene=scene)
                    is None]
    modelled = [e for e in ESTIMATORS.names()
                if ESTIMATORS.why_not(e, scene=scene, formulation="vi") is None]
    assert {"residual", "averaging"} <= set(modelled)
    for estimator in modelled:
        rows = [level.row for level in run_sequence(
            scene, "vi", "active-set", estimator,
            LoopConfig(strategy="adaptive", max_dofs=1500))]
        assert all(r.status in SOLVED for r in rows), [r.reason for r in rows]
        last = rows[-1]
        assert last.friction == "coulomb(mu=0.3)" and last.stick_points + last.slip_points > 0
        # in 3D the zone is its extent along x: inside the contact face (-1, 1)
        assert -1 <= last.stick_zone_start <= last.stick_zone_end <= 1
        assert np.isfinite(last.eta) and last.eta > 0


def test_mindlin_stick_radius_and_shear_at_hand_worked_numbers():
    from scenes.base import Material
    from scenes.hertz_3d import mindlin
    # E = 1000, nu = 0, R = 1, P = 4000/3: a = 1, p0 = 2000/pi (Hertz); Q = (7/8) mu P leaves
    # c = a (1/8)^(1/3) = 1/2, and q(0) = mu p0 (1 - c/a) (Johnson, Contact Mechanics, 7.2)
    P, mu = 4000.0 / 3.0, 0.3
    predicted = mindlin(mu, 1e-3)(Material(1000.0, 0.0, "strain"), 1.0, P, 7 / 8 * mu * P)
    assert predicted.stick_half_width == pytest.approx(0.5, rel=1e-14)
    assert predicted.shear(np.array([0.0]))[0] == pytest.approx(mu * 2000 / np.pi * 0.5,
                                                                  rel=1e-14)


def test_a_sliding_obstacle_drags_the_sticking_nodes_along_x_in_3d():
    # mu = 10 sticks every node in contact (section 17.6), so there u_h = w = slide e_x
    scene = get_scene("hertz-3d", friction="coulomb", mu=10.0, slide=1e-3, initial_divisions=4)
    disc = get_formulation("vi")(scene, scene.mesh.refined(1))
    sol = solve(disc, "active-set")
    assert sol.status == "ok", sol.reason
    stick = sol.friction.state == "stick"
    assert stick.sum() >= 1
    slip = sol.friction.slip  # T u - w per node and tangent: zero where a node sticks
    assert np.abs(slip.reshape(-1, 2)[stick]).max() < 1e-12  # exact sets: round-off
    frame = np.array(disc.qp.friction.shift).reshape(-1, 2)
    assert np.abs(frame).max() == pytest.approx(1e-3, rel=1e-12)  # w . t_k = slide (t_k)_x

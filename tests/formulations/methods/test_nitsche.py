"""Nitsche's method: its equation solved to round-off for every variant and order, the
semismooth Newton solver against the reference where a convex form exists, the sign of
lambda_h, coercivity of the symmetric variant, and agreement with the other formulations."""

import numpy as np
import pytest
from scipy import sparse
from scipy.linalg import eigh

from formulations import get_formulation, solve
from formulations.cells.evaluation import evaluate_on_trace
from formulations.discretisation import why_unsolvable
from formulations.methods.nitsche import DEFAULT_GAMMA_0
from formulations.registry import FORMULATIONS
from formulations.solvers.backends import available_backends
from formulations.solvers.sparse_newton import system_matrix
from scenes import get_scene, scene_names

THETAS = (1.0, 0.0, -1.0)
# the nonlinear residual K u + T'phi(Tu) - F relative to max(|Ku|, |F|, |T'phi|): the dense
# and sparse solves leave 1e-13..3e-12 (measured up to 5e5 DOFs); 1e-10 is round-off with a
# margin of the condition number of K (~1e5 here) times eps, not a solver tolerance
ROUNDOFF = 1e-10


def discretised(theta=1.0, refinements=3, order=1, scene="paper", **options):
    scene = get_scene(scene)
    return get_formulation("nitsche")(scene, scene.mesh.refined(refinements), theta=theta,
                                      order=order, **options)


@pytest.mark.parametrize("backend", available_backends())
@pytest.mark.parametrize("theta", THETAS)
def test_every_variant_solves_its_equation_to_roundoff(theta, backend):
    disc = discretised(theta)
    sol = solve(disc, "active-set", backend=backend)
    assert sol.status == "ok", sol.reason
    u = sol.u[disc.elasticity.free]
    r = disc.system.residual(u)
    scale = max(np.linalg.norm(disc.system.K @ u), np.linalg.norm(r + disc.system.F))
    assert np.linalg.norm(r) <= ROUNDOFF * scale
    assert sol.residuals.stationarity <= ROUNDOFF
    # converged means the last active set reproduced itself: the final Newton matrix with
    # that active set maps u to F up to the same round-off
    active = disc.system.pressure_argument(disc.system.T @ u) < 0
    D, c = disc.system.phi_affine(active)
    J = system_matrix(disc.system, active)
    assert np.linalg.norm(J @ u + disc.system.T.T @ c - disc.system.F) <= ROUNDOFF * scale
    assert sol.diagnostics.active_set_changes[-1] == 0


@pytest.mark.parametrize("theta, order", [(1.0, 1), (-1.0, 2)])
def test_the_consistency_term_is_what_the_equation_adds_to_the_tractions(theta, order):
    # K u - F + N'(W lambda_h) - c = 0 with c_i = sum_q w_q q_q . sigma(phi_i) n, c assembled
    # here from the stored q, weights and points by the traction sigma(v) n component by
    # component (not by sigma_nn): the residual is the solve's round-off (ROUNDOFF)
    disc = discretised(theta, refinements=2, order=order)
    sol = solve(disc, "active-set")
    term, trace, elasticity = sol.consistency, sol.trace, disc.elasticity
    nq = term.points.shape[-1]
    at = evaluate_on_trace(elasticity.basis, trace, term.points)
    normal = np.repeat(trace.normal, nq, axis=1)
    vector = term.vector.reshape(2, -1)
    c = sum(elasticity.restrict(at.stress_matrix(normal, np.repeat(axis[:, None], normal.shape[1],
                                                                   axis=1), elasticity.lame)
                                ).T @ (term.weights * vector[j])
            for j, axis in enumerate(np.eye(2)))
    u = sol.u[elasticity.free]
    lam = sol.pressure(term.points).ravel()
    residual = disc.system.K @ u - disc.system.F + disc.system.N.T @ (term.weights * lam) - c
    scale = max(np.linalg.norm(disc.system.K @ u), np.linalg.norm(disc.system.F))
    assert np.linalg.norm(residual) <= ROUNDOFF * scale
    assert np.linalg.norm(c) >= 1e-6 * scale  # the term is there to be found
    across = vector[0] * normal[1] - vector[1] * normal[0]
    assert np.abs(across).max() <= 1e-12 * np.abs(vector).max()  # along n without friction


@pytest.mark.parametrize("order", [1, 2, 3])
def test_the_symmetric_variant_agrees_with_the_reference_solver(order):
    disc = discretised(1.0, refinements=3 if order == 1 else 2, order=order)
    fast, judge = solve(disc, "active-set"), solve(disc, "reference")
    assert fast.status == "ok" and judge.status == "ok", (fast.reason, judge.reason)
    # Clarabel's tolerances 1e-10 on the scaled problem: measured differences ~6e-10 in u
    # (relative max) and ~1e-7 in the contact force; 1e-7 and 1e-5 leave a margin of 100
    du = np.abs(fast.u - judge.u).max() / np.abs(fast.u).max()
    assert du <= 1e-7, du
    assert fast.contact_force() == pytest.approx(judge.contact_force(), rel=1e-5)
    assert fast.energy == pytest.approx(judge.energy, rel=1e-8)


@pytest.mark.parametrize("theta", [0.0, -1.0])
def test_the_nonsymmetric_variants_have_no_qp_and_are_skipped_for_the_reference(theta):
    disc = discretised(theta, refinements=1)
    assert disc.qp is None and "convex functional" in disc.no_qp
    assert "needs a QP" in why_unsolvable(disc, "reference")
    with pytest.raises(ValueError, match="needs a QP"):
        solve(disc, "reference")
    assert f"theta={theta:g}" in why_unsolvable(disc, "reference")
    assert why_unsolvable(discretised(1.0, refinements=1), "reference") is None


def test_lambda_h_is_the_negative_part_of_the_nitsche_pressure_and_presses():
    disc = discretised(1.0, refinements=5)
    sol = solve(disc, "active-set")
    t = np.linspace(0.0, 1.0, 5)
    lam = sol.pressure(t)
    assert lam.min() >= 0.0 and lam.max() > 0.0  # exact: the negative part of a value
    # the forces of two converging methods (measured on paper: 5863.8 against mixed's 5866.4
    # at 33 024 DOFs, 0.05 %); 1 % is a tenth of their difference at 544 DOFs
    assert sol.contact_force() > 0
    mixed = solve(get_formulation("mixed")(get_scene("paper"), disc.elasticity.mesh),
                  "active-set")
    assert sol.contact_force() == pytest.approx(mixed.contact_force(), rel=0.01)
    # the quadrature points in contact: lambda_h > 0 exactly where P_gamma < 0
    P = disc.system.pressure_argument(disc.system.T @ sol.u[disc.elasticity.free])
    assert sol.active_constraints == int((P < 0).sum()) > 0


@pytest.mark.parametrize("order, measured", [(1, 1.957), (2, 6.28),
                                             pytest.param(3, 12.97, marks=pytest.mark.slow)])
def test_the_default_gamma_0_makes_the_symmetric_variant_coercive(order, measured):
    # a(v, v) - 1/gamma ||sigma_nn(v)||^2_C >= 0 iff gamma_0 >= the largest eigenvalue mu of
    # (S' W h/E S) v = mu K v (gamma = gamma_0 E / h); mesh-independent on uniform meshes
    disc = discretised(1.0, refinements=1, order=order, gamma_0=1.0)
    s = disc.system
    A = (s.S.T @ sparse.diags(s.weight / s.gamma) @ s.S).toarray()
    mu = eigh(A, s.K.toarray(), eigvals_only=True)[-1]
    assert mu == pytest.approx(measured, rel=1e-3)
    assert DEFAULT_GAMMA_0 >= 5 * mu  # the default keeps a margin of at least 5


# the 2D scenes (four uniform refinements of a 3D scene would be 6.7e6 DOFs)
@pytest.mark.parametrize("scene", [s for s in scene_names() if "hard" not in get_scene(s).tags
                                   and get_scene(s).dim == 2
                                   and all(FORMULATIONS.why_not(f, scene=get_scene(s)) is None
                                           for f in ("mixed", "nitsche"))])
def test_nitsche_and_mixed_converge_to_one_solution(scene):
    # energy and contact force of nitsche and mixed (both exact solves) at two uniform levels:
    # they converge to one limit, so their difference must at least halve over two
    # refinements (measured: paper energy 8.0 -> 0.45, force 33 -> 12; hertz 2.9e-3 ->
    # 2.3e-4 and 33 -> 0.06; free-boundary 3.3e-8 -> 2.3e-10 and 1.9e-5 -> 2.5e-7)
    base = get_scene(scene)
    gaps = []
    for refinements in (2, 4) if scene != "hertz" else (1, 3):
        mesh = base.mesh.refined(refinements)
        a = solve(get_formulation("nitsche")(base, mesh), "active-set")
        b = solve(get_formulation("mixed")(base, mesh), "active-set")
        assert a.ok and b.ok, (a.reason, b.reason)
        gaps.append((abs(a.energy - b.energy), abs(a.contact_force() - b.contact_force())))
    assert gaps[1][0] <= gaps[0][0] / 2 and gaps[1][1] <= gaps[0][1] / 2, gaps


@pytest.mark.parametrize("option, value, message", [
    ("theta", 2.0, "theta=2.0 is not a number in [-1, 1]"),
    ("theta", "x", "theta='x' is not a number in [-1, 1]"),
    ("gamma_0", 0.0, "gamma_0=0.0 is not a finite number > 0"),
    ("gamma_0", float("inf"), "gamma_0=inf is not a finite number > 0"),
])
def test_bad_options_are_refused_with_the_value(option, value, message):
    with pytest.raises(ValueError, match=message.replace("[", r"\[").replace("]", r"\]")):
        discretised(**{"theta": 1.0, option: value}, refinements=0)


def test_nested_iteration_settles_in_a_few_newton_steps():
    scene = get_scene("paper")
    coarse = solve(get_formulation("nitsche")(scene, scene.mesh.refined(4)), "active-set")
    fine = get_formulation("nitsche")(scene, scene.mesh.refined(5))
    cold = solve(fine, "active-set")
    warm = solve(fine, "active-set", warm_start=fine.warm_start(coarse))
    assert warm.ok and cold.ok
    # measured: 15 iterations cold, 4 warm at 33 024 DOFs
    assert warm.iterations <= 6 < cold.iterations
    assert warm.energy == pytest.approx(cold.energy, rel=1e-12)

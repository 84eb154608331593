"""The mixed method: B and G, the contact mesh, and the QP solved by the reference solver."""

import numpy as np
import pytest

from conftest import square_scene
from formulations import get_formulation, solve
from formulations.methods.mixed import multiplier_segments
from scenes import get_scene

discretise = get_formulation("mixed")


def test_B_integrates_normal_displacement_and_G_integrates_a_linear_gap_exactly():
    a, b = 0.3, -0.05
    scene = square_scene(lambda x: a * x[0] + b, divisions=4)
    disc = discretise(scene, scene.mesh.refined(2))
    trace = disc.trace
    seg = multiplier_segments(trace.length)
    x0 = np.array([trace.coordinate[0, seg == i].min() for i in range(disc.qp.m)])
    x1 = np.array([trace.coordinate[1, seg == i].max() for i in range(disc.qp.m)])
    assert disc.qp.G == pytest.approx(a * (x1**2 - x0**2) / 2 + b * (x1 - x0), rel=1e-13)
    # a field with u_y = alpha x + beta: u.n = -(alpha x + beta) since n = (0, -1)
    alpha, beta, ux = 0.2, 0.7, 5.0
    p = disc.elasticity.mesh.p
    u = np.zeros(disc.elasticity.basis.N)
    u[disc.elasticity.basis.nodal_dofs[0]] = ux  # tangential part must not contribute
    u[disc.elasticity.basis.nodal_dofs[1]] = alpha * p[0] + beta
    Bu = disc.qp.B @ u[disc.elasticity.free]
    assert Bu == pytest.approx(-(alpha * (x1**2 - x0**2) / 2 + beta * (x1 - x0)), rel=1e-13)


def test_paper_gap_integral_matches_closed_form():
    # int_{-1}^{1} 0.85 - sqrt(1 - x^2) dx = 1.7 - pi/2; the sqrt end-point singularity limits
    # Gauss quadrature on the two end facets to ~h^1.5 accuracy, hence the tolerance
    scene = get_scene("paper")
    disc = discretise(scene, scene.mesh.refined(3))
    assert disc.qp.G.sum() == pytest.approx(1.7 - np.pi / 2, abs=1e-4)


def test_contact_mesh_satisfies_h_over_H_on_adaptive_meshes():
    scene = get_scene("paper")
    rng = np.random.default_rng(1)
    mesh = scene.mesh.refined(1)
    for _ in range(6):
        marked = rng.choice(mesh.t.shape[1], size=max(1, mesh.t.shape[1] // 5), replace=False)
        mesh = mesh.refined(np.sort(marked))
        disc = discretise(scene, mesh)
        trace = disc.trace
        seg = multiplier_segments(trace.length)
        H = np.bincount(seg, trace.length)
        assert (trace.length / H[seg]).max() <= 0.5 + 1e-12
        # segments are contiguous and cover Gamma_C
        assert (np.diff(seg) >= 0).all() and H.sum() == pytest.approx(2.0, rel=1e-14)
    assert len(np.unique(np.round(trace.length, 12))) > 2  # the mesh is really graded


@pytest.mark.parametrize("lengths, expected", [
    ([1, 1, 1, 1], [0, 0, 1, 1]),                 # uniform: pairs, H = 2h
    ([2, 1, 1, 0.5, 0.5, 0.5, 0.5], [0, 0, 0, 1, 1, 2, 2]),  # graded: follows the grading
    ([1, 1, 1], [0, 0, 0]),                       # odd remainder merged backwards
    ([0.25, 0.25, 0.5, 2, 1, 1], [0, 0, 1, 1, 1, 1]),  # a long facet forces a long segment
])
def test_segments_are_the_shortest_runs_with_h_over_H_at_most_half(lengths, expected):
    seg = multiplier_segments(np.array(lengths, dtype=float))
    assert seg.tolist() == expected
    H = np.bincount(seg, np.array(lengths, dtype=float))
    # a ratio of sums of the given lengths: 1/2 up to a few ulps (the builder allows 1e-12)
    assert (np.array(lengths) / H[seg]).max() <= 0.5 + 1e-12


def test_exact_linear_solution_is_reproduced(compression_scene):
    disc = discretise(compression_scene, compression_scene.mesh.refined(1))
    sol = solve(disc, "reference")
    assert sol.status == "ok", sol.reason
    y = disc.elasticity.mesh.p[1]
    nodal = disc.elasticity.nodal(sol.u)
    # u = (0, delta (1 - y) / 2) with delta = 0.01; Clarabel's 1e-9 tolerances bound the error
    assert np.abs(nodal[1] - 0.005 * (1 - y)).max() < 1e-8
    assert np.abs(nodal[0]).max() < 1e-8
    # lambda_H = E delta / 2 = 5 on every segment; contact force = 5 * |Gamma_C| = 10
    assert sol.multipliers == pytest.approx(5.0, rel=1e-7)
    assert sol.contact_force() == pytest.approx(10.0, rel=1e-7)
    assert sol.active_constraints == disc.qp.m


def test_reference_solution_satisfies_kkt_conditions():
    scene = get_scene("paper")
    disc = discretise(scene, scene.mesh.refined(3))
    sol = solve(disc, "reference")
    assert sol.status == "ok", sol.reason
    r = sol.residuals
    # Clarabel stops at 1e-9 relative gap/feasibility on the scaled problem; 1e-6 leaves room for
    # the rescaling back to physical units (K ~ E = 7e4, rows of B ~ h)
    assert max(r.violation, r.dual_violation, r.complementarity, r.stationarity) < 1e-6
    # and the same checks written out independently of formulations.kkt
    u, lam = sol.u[disc.elasticity.free], sol.multipliers
    qp = disc.qp
    # an interior point method's multipliers are >= 0 up to its tolerance 1e-9 (relative)
    assert lam.min() >= -1e-9 * np.abs(lam).max()
    assert ((qp.B @ u - qp.G) / qp.row_scale).max() < 1e-9
    stationarity = qp.K @ u - qp.F + qp.B.T @ lam
    assert np.linalg.norm(stationarity) < 1e-6 * np.linalg.norm(qp.K @ u)
    assert abs(lam @ (qp.B @ u - qp.G)) < 1e-6 * (u @ qp.K @ u)
    assert 0 < sol.active_constraints < qp.m  # a genuine free boundary inside Gamma_C


def test_solver_that_stops_early_reports_status_and_reason():
    scene = get_scene("paper")
    disc = discretise(scene, scene.mesh.refined(3))
    sol = solve(disc, "reference", max_iter=2)
    assert sol.status in ("failed", "inaccurate")
    assert sol.reason  # never a silent failure

"""The ``amg`` back-end's smoothed-aggregation hierarchy is PyAMG's, its spectral radius
estimated in single precision from a fixed start."""

import numpy as np
import pytest
from scipy import sparse
from scipy.sparse.linalg import eigsh, norm

from formulations import get_formulation
from formulations.solvers.backends import amg, amg_hierarchy
from scenes import get_scene

CASES = [("paper", 3), ("paper-3d", 1)]


def problem(scene, refine):
    scene = get_scene(scene)
    qp = get_formulation("vi")(scene, scene.mesh.refined(refine)).qp
    K = sparse.csr_matrix(qp.K)
    return K, K.astype(amg.CYCLE_DTYPE), np.asarray(qp.near_null, dtype=amg.CYCLE_DTYPE)


def pyamgs(K32, modes):
    import pyamg

    return pyamg.smoothed_aggregation_solver(
        K32, B=modes, symmetry="symmetric",
        strength=amg_hierarchy.strength_per_level(),
        max_coarse=amg_hierarchy.MAX_COARSE, coarse_solver="splu", keep=True)


@pytest.mark.parametrize("scene,refine", CASES)
def test_the_prolongation_is_pyamgs_jacobi_step_with_an_accurate_radius(scene, refine):
    """P = T - 4/3 / rho D^-1 K T with PyAMG's own tentative T (same aggregates, same improved
    candidates), and rho within PyAMG's 1e-2 of D^-1 K's largest eigenvalue (ARPACK, double)."""
    K, K32, modes = problem(scene, refine)
    ours, theirs = amg_hierarchy.smoothed_aggregation(K32, modes), pyamgs(K32, modes)
    assert [level.A.shape for level in ours.levels] == [level.A.shape for level in theirs.levels]
    assert all(level.A.dtype == amg.CYCLE_DTYPE for level in ours.levels)
    T = sparse.csr_matrix(theirs.levels[0].T).astype(float)
    d = 1.0 / K.diagonal()
    direction = sparse.csr_matrix(sparse.diags(d) @ K @ T)
    correction = T - sparse.csr_matrix(ours.levels[0].P).astype(float)
    # least squares: 4/3 / rho
    scale = correction.multiply(direction).sum() / direction.multiply(direction).sum()
    # the rest is float32 round-off of the product (eps 6e-8 times a few terms per entry)
    assert norm(correction - scale * direction) <= 1e-5 * norm(correction)
    scaled = sparse.diags(np.sqrt(d)) @ K @ sparse.diags(np.sqrt(d))  # similar to D^-1 K
    largest = eigsh(scaled, k=1, which="LA", tol=1e-10, return_eigenvectors=False)[0]
    # Arnoldi's Ritz value lies below the eigenvalue; PyAMG's stopping tolerance is 1e-2
    assert abs(amg_hierarchy.OMEGA / scale - largest) <= 1e-2 * largest


def test_the_hierarchy_is_the_same_on_every_build():
    """A seeded start vector: two builds give the same prolongation to the last bit (PyAMG's
    random start gave a different one on each build)."""
    _, K32, modes = problem("paper-3d", 1)
    first, second = (amg_hierarchy.smoothed_aggregation(K32, modes) for _ in range(2))
    assert np.array_equal(first.levels[0].P.data, second.levels[0].P.data)


@pytest.mark.parametrize("scene,refine", CASES)
def test_cg_takes_as_many_iterations_as_with_pyamgs_hierarchy(scene, refine):
    """The same cycle on either hierarchy: the iteration counts to RTOL agree to one (their
    radii differ within the estimator's 1e-2)."""
    K, K32, modes = problem(scene, refine)
    b = K @ np.random.default_rng(0).standard_normal(K.shape[0])
    counts = []
    for hierarchy in (amg_hierarchy.smoothed_aggregation(K32, modes), pyamgs(K32, modes)):
        amg.in_single(hierarchy)
        solve = amg.IterativeSolve(K, amg.VCycle(hierarchy), True)
        solve(b)
        counts += solve.iterations
    assert abs(counts[0] - counts[1]) <= 1


@pytest.mark.slow
def test_the_coarse_threshold_keeps_the_iterations_from_growing_with_the_levels(monkeypatch):
    """paper-3d at 104 544 P1 DOFs, three levels: with theta = 0 below the finest level the
    aggregates grow (113 nodes each on level 1 against 25 on level 0) and CG took 42
    iterations for the load that took 22 at 9 450 DOFs on two levels; with COARSE_THETA 32.
    Asserted: at most 1.5 times the two-level count (the mesh-independence aimed at), and
    fewer than with theta = 0 everywhere."""
    from bench.perf.scaling import linear_rhs
    from bench.perf.scaling_3d import paper_3d_problem

    counts, coarse = {}, amg_hierarchy.COARSE_THETA
    for size in ("1e4", "1e5"):
        qp = get_formulation("vi")(*paper_3d_problem(size)).qp
        for theta in (0.0, coarse):
            monkeypatch.setattr(amg_hierarchy, "COARSE_THETA", theta)
            solve = amg.factorise(qp.K, qp.near_null)
            solve(linear_rhs(qp))
            counts[size, theta] = solve.iterations[0]
    assert counts["1e5", coarse] <= 1.5 * counts["1e4", coarse], counts
    assert counts["1e5", coarse] < counts["1e5", 0.0], counts

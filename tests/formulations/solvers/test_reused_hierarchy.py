"""Newton steps that reuse the last multigrid hierarchy (docs/theory.md, section 16): a reused
step answers to the tolerance asked, a Jacobian too far from the held one or not symmetric gets
a hierarchy of its own."""

import numpy as np
import pytest
from scipy import sparse

from formulations import get_formulation
from formulations.solvers import reused_hierarchy
from formulations.solvers.reused_hierarchy import ReusedHierarchy
from scenes import get_scene

pytest.importorskip("pyamg")
RTOL = 1e-10


@pytest.fixture(scope="module")
def stiffness():
    scene = get_scene("paper")
    qp = get_formulation("vi")(scene, scene.mesh.refined(3)).qp
    return sparse.csr_matrix(qp.K), qp.near_null


def contact_jacobian(K, points: np.ndarray, weight: float) -> sparse.csr_matrix:
    """K plus a penalty-like term on the given DOFs (what an active contact point adds)."""
    d = np.zeros(K.shape[0])
    d[points] = weight * K.diagonal()[points]
    return sparse.csr_matrix(K + sparse.diags(d))


def relative_residual(J, x, b) -> float:
    return float(np.linalg.norm(b - J @ x) / np.linalg.norm(b))


def test_a_small_change_reuses_the_hierarchy(stiffness, monkeypatch):
    """With a budget that does not hang on this machine's timings, a few changed points keep
    the hierarchy (the budget's size is a cost question, measured in docs/theory.md 16)."""
    monkeypatch.setattr(reused_hierarchy, "MIN_BUDGET", 200)
    K, modes = stiffness
    steps = ReusedHierarchy("amg", modes)
    b = np.random.default_rng(0).standard_normal(K.shape[0])
    for points in (np.arange(0, 40, 2), np.arange(0, 44, 2), np.arange(2, 46, 2)):
        J = contact_jacobian(K, points, 10.0)
        x = steps(J, b, RTOL)
        assert relative_residual(J, x, b) <= 10 * RTOL  # CG's own test, with its slack
    assert steps.setups == 1


@pytest.fixture
def thirty_iterations(monkeypatch):
    """A budget of 30 iterations, whatever this machine's timings."""
    monkeypatch.setattr(reused_hierarchy, "MIN_BUDGET", 30)
    monkeypatch.setattr(reused_hierarchy, "BUDGET", 0.0)


def stiff_third(K):
    return contact_jacobian(K, np.arange(0, K.shape[0], 3), 1e4)  # a third of the DOFs, stiff


def nonsymmetric(K):
    skew = sparse.random(K.shape[0], K.shape[0], density=1e-4, random_state=3) * 1e-3
    return sparse.csr_matrix(K + (skew - skew.T) * abs(K).max())


@pytest.mark.usefixtures("thirty_iterations")
@pytest.mark.parametrize("jacobian", [stiff_third, nonsymmetric])
def test_a_jacobian_the_held_hierarchy_cannot_serve_gets_its_own(stiffness, jacobian):
    K, modes = stiffness
    steps = ReusedHierarchy("amg", modes)
    b = np.random.default_rng(1).standard_normal(K.shape[0])
    steps(K, b, RTOL)
    J = jacobian(K)
    x = steps(J, b, RTOL)
    assert relative_residual(J, x, b) <= 10 * RTOL
    assert steps.setups == 2


def test_many_changed_points_build_a_hierarchy_without_trying_the_old_one(stiffness):
    K, modes = stiffness
    steps = ReusedHierarchy("amg", modes)
    b = np.random.default_rng(4).standard_normal(K.shape[0])
    active = np.zeros(K.shape[0] // 2, dtype=bool)
    steps(K, b, RTOL, active)
    J = contact_jacobian(K, np.arange(0, 40, 2), 10.0)   # a small change ...
    steps(J, b, RTOL, ~active)                            # ... but every point flipped
    assert steps.setups == 2
    assert len(steps.iterations) == 2  # no attempt with the old hierarchy in between


@pytest.mark.usefixtures("thirty_iterations")
def test_after_failed_attempts_in_a_row_the_solve_stops_trying(stiffness):
    K, modes = stiffness
    steps = ReusedHierarchy("amg", modes)
    b = np.random.default_rng(5).standard_normal(K.shape[0])
    steps(K, b, RTOL)
    stiff = [contact_jacobian(K, np.arange(start, K.shape[0], 3), 1e4) for start in (0, 1, 2)]
    for J in stiff[:reused_hierarchy.GIVE_UP]:
        steps(J, b, RTOL)  # each attempt fails, and the step builds its own hierarchy
    count = len(steps.iterations)
    assert steps.setups == 1 + reused_hierarchy.GIVE_UP
    assert count == 1 + 2 * reused_hierarchy.GIVE_UP
    steps(stiff[-1], b, RTOL)
    assert len(steps.iterations) == count + 1  # built at once, no attempt first
